// Fuzz target: the gsf height-map reader (formats::decode_gsf), exactly as read_height_map()
// drives it with a file's bytes. Seeds: fuzz/corpus/height_gsf/ (fuzz/make_height_seeds_x3p.py).
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        (void)roughscope::surface::formats::decode_gsf(roughscope::fuzz::as_text(data, size),
                                                       "fuzz.gsf", {});
    });
    return 0;
}
