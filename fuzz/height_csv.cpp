// Fuzz target: the CSV/ASCII matrix and XYZ height readers (surface/formats.hpp) on the same
// bytes; a matrix that reads must survive the writer and read back bit for bit.
#include <cstdlib>
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace s = roughscope::surface;
    const std::string_view text = roughscope::fuzz::as_text(data, size);
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        const s::HeightMap map = s::formats::decode_csv_matrix(text, "fuzz.csv", {});
        const std::string again = s::formats::encode_csv_matrix(map, {});
        if (!s::bitwise_equal(map, s::formats::decode_csv_matrix(again, "again.csv", {}))) {
            std::abort();
        }
    });
    roughscope::fuzz::expect_only_roughscope_errors(
        [&] { (void)s::formats::decode_xyz(text, "fuzz.xyz", {}); });
    return 0;
}
