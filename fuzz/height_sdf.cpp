// Fuzz target: the ISO 25178-71 SDF reader (binary and ASCII, surface/formats.hpp); a map that
// reads must survive both writers and read back bit for bit.
#include <cstdlib>
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace s = roughscope::surface;
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        const s::HeightMap map =
            s::formats::decode_sdf(roughscope::fuzz::as_text(data, size), "fuzz.sdf", {});
        for (const bool binary : {true, false}) {
            s::HeightWriteOptions options;
            options.sdf_binary = binary;
            roughscope::fuzz::expect_only_roughscope_errors([&] {
                const std::string again = s::formats::encode_sdf(map, options);
                if (!s::bitwise_equal(map, s::formats::decode_sdf(again, "again.sdf", {}))) {
                    std::abort();
                }
            });
        }
    });
    return 0;
}
