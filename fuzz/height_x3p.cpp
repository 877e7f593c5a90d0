// Fuzz target: the x3p height-map reader (formats::decode_x3p, checksums verified), exactly as
// read_height_map() drives it with a file's bytes. Seeds: fuzz/corpus/height_x3p/
// (fuzz/make_height_seeds_x3p.py).
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        (void)roughscope::surface::formats::decode_x3p(roughscope::fuzz::as_text(data, size),
                                                       "fuzz.x3p", {});
    });
    return 0;
}
