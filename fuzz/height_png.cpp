// Fuzz target: the PNG height-image reader (libpng from memory, surface/formats.hpp) with a z
// scale of 1 µm per count; an image that reads must survive the 16-bit writer bit for bit.
#include <cstdlib>
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace s = roughscope::surface;
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        s::HeightReadOptions options;
        options.z_scale_um = 1.0;
        const s::HeightMap map =
            s::formats::decode_png(roughscope::fuzz::as_text(data, size), "fuzz.png", options);
        s::HeightWriteOptions write;
        write.z_scale_um = 1.0;
        const std::string again = s::formats::encode_png(map, write);
        if (!s::bitwise_equal(map, s::formats::decode_png(again, "again.png", options))) {
            std::abort();
        }
    });
    return 0;
}
