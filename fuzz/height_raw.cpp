// Fuzz target: the raw float32/float64 height reader (surface/formats.hpp). Byte 0 picks the
// sample type (bit 0), the byte order (bit 1) and whether ny is one too many (bit 2, the size
// error path); byte 1 gives nx (1 to 256); the rest is the file. A float64 little-endian map that
// reads must survive the writer bit for bit.
#include <cstdlib>
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/surface/formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace s = roughscope::surface;
    if (size < 2) return 0;
    s::HeightReadOptions options;
    options.raw_type = (data[0] & 1U) != 0 ? s::RawSampleType::Float32 : s::RawSampleType::Float64;
    options.raw_big_endian = (data[0] & 2U) != 0;
    const std::size_t sample = options.raw_type == s::RawSampleType::Float32 ? 4 : 8;
    const std::size_t nx = std::size_t{data[1]} + 1;
    const std::string_view file = roughscope::fuzz::as_text(data + 2, size - 2);
    options.nx = nx;
    options.ny = file.size() / (nx * sample) + ((data[0] & 4U) != 0 ? 1 : 0);
    options.dx_um = 0.5;
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        const s::HeightMap map = s::formats::decode_raw(file, "fuzz.raw", options);
        if (options.raw_type == s::RawSampleType::Float64 && !options.raw_big_endian) {
            const std::string again = s::formats::encode_raw(map, {});
            if (!s::bitwise_equal(map, s::formats::decode_raw(again, "again.raw", options))) {
                std::abort();
            }
        }
    });
    return 0;
}
