// Fuzz target: a BRDF table CSV (brdf/table.hpp parse_brdf_csv, as `roughscope curet --table
// FILE` reads it), once for every channel and once keeping only the channel "red".
#include "fuzz_target.hpp"
#include "roughscope/brdf/table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text = roughscope::fuzz::as_text(data, size);
    roughscope::fuzz::expect_only_roughscope_errors(
        [&] { (void)roughscope::parse_brdf_csv(text, "table.csv"); });
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        roughscope::BrdfCsvOptions options;
        options.channel = "red";
        const roughscope::BrdfTable table = roughscope::parse_brdf_csv(text, "table.csv", options);
        for (const auto& m : table.measurements) (void)table.find(m.index);
    });
    return 0;
}
