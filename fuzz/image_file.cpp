// Fuzz target: the photograph reader (image/read.hpp: PNG through libpng, TIFF through libtiff,
// JPEG through libjpeg, camera RAW through LibRaw, EXIF through libexif, ICC profiles), chosen by
// the input's first bytes, with the default options and again with explicit levels, response and
// white balance. An image that reads must be consistent (check_linear_image) and carry the flags
// and levels it reports.
#include <cstdlib>
#include <span>
#include <vector>

#include "fuzz_target.hpp"
#include "roughscope/photo/read.hpp"

namespace {

void check_or_abort(const roughscope::image::LinearImage& image) {
    try {
        roughscope::image::check_linear_image(image);
    } catch (const roughscope::Error&) {
        std::abort();  // the reader returned an inconsistent image
    }
    if (image.info.black_level_dn.size() != image.channels || !(image.info.white_level_dn > 0.0))
        std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace im = roughscope::image;
    const std::span<const std::uint8_t> bytes(data, size);
    roughscope::fuzz::expect_only_roughscope_errors(
        [&] { check_or_abort(im::decode_image(bytes, "fuzz.img")); });
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        im::ReadOptions options;
        options.response = roughscope::Response::Gamma;
        options.gamma = 2.2;
        options.black_level_dn = std::vector<double>{1.0};
        options.white_level_dn = 200.0;
        options.white_balance = true;
        check_or_abort(im::decode_image(bytes, "fuzz.img", options));
    });
    return 0;
}
