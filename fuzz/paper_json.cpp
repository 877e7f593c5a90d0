// Fuzz target: the paper-tables JSON document that `roughscope paper tables` reads
// (cli/paper.cpp): parsed with nlohmann::json (a parse error is the command's DataError), then
// recomputed by serialize::recompute_paper_tables (§4 estimators, Tables 1-3) and serialized.
#include <nlohmann/json.hpp>

#include "fuzz_target.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/paper_tables.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace serialize = roughscope::serialize;
    // The command turns a parse error into a DataError naming the file: expected.
    const serialize::Json reference =
        serialize::Json::parse(data, data + size, /*cb=*/nullptr, /*allow_exceptions=*/false);
    if (reference.is_discarded()) return 0;
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        const serialize::Json tables = serialize::recompute_paper_tables(reference, "tables.json");
        (void)serialize::dump(tables);
    });
    return 0;
}
