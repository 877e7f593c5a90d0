// Fuzz target: the capture file of `roughscope measure` (image/measure.hpp,
// parse_capture_file): JSON to a MeasureRequest, every key checked. A DataError naming the key is
// the answer to anything malformed. Images named in the input are not read (only a `mask`
// region's file is, which the corpus never names).
#include "fuzz_target.hpp"
#include "roughscope/measure/measure.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        const roughscope::image::MeasureRequest request = roughscope::image::parse_capture_file(
            roughscope::fuzz::as_text(data, size), "fuzz/capture.json");
        (void)request.captures.size();
    });
    return 0;
}
