// Fuzz target: the x3p height-map reader (formats::decode_x3p), exactly as read_height_map()
// drives it with a file's bytes, once with the checksums verified (the default) and once without
// (--no-verify-checksums: mutated data that an MD5 checksum would stop reaches the conversion and
// the checks after it). Seeds: fuzz/corpus/height_x3p/
// (fuzz/make_height_seeds_x3p.py).
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto bytes = roughscope::fuzz::as_text(data, size);
    roughscope::surface::HeightReadOptions unverified;
    unverified.x3p_verify_checksums = false;
    for (const auto& options : {roughscope::surface::HeightReadOptions{}, unverified}) {
        roughscope::fuzz::expect_only_roughscope_errors(
            [&] { (void)roughscope::surface::formats::decode_x3p(bytes, "fuzz.x3p", options); });
    }
    return 0;
}
