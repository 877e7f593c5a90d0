// Fuzz target: the TIFF height-image reader (libtiff on memory, surface/formats.hpp) with a z
// scale of 1 µm per count for integer samples.
#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace s = roughscope::surface;
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        s::HeightReadOptions options;
        options.z_scale_um = 1.0;
        (void)s::formats::decode_tiff(roughscope::fuzz::as_text(data, size), "fuzz.tif", options);
    });
    return 0;
}
