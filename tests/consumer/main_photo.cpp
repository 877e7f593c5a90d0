// Downstream consumer of the photograph-reading topic alone (roughscope::photo): decodes a
// 2 × 1 8-bit grey PNG held in memory (written from the PNG specification: signature, IHDR,
// one zlib-compressed IDAT row [filter 0, pixels 0 and 255], IEND) and checks the two linear
// values. Linked without the fit engine (Ceres) or the brdf topic (cmake/RunConsumerTest.cmake
// checks its link line).
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <roughscope/photo/read.hpp>
#include <roughscope/version.hpp>

int main() {
    static constexpr std::array<std::uint8_t, 68> png = {
        0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
        0x44, 0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x00, 0x00, 0x00,
        0x00, 0xd1, 0x49, 0x20, 0x56, 0x00, 0x00, 0x00, 0x0b, 0x49, 0x44, 0x41, 0x54, 0x78,
        0x9c, 0x63, 0x60, 0xf8, 0x0f, 0x00, 0x01, 0x02, 0x01, 0x00, 0x42, 0xbe, 0xbc, 0x68,
        0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
    const roughscope::image::LinearImage image =
        roughscope::image::decode_image(png, "consumer.png");
    const bool ok = image.width == 2 && image.height == 1 && image.channels == 1 &&
                    std::abs(image.value(0, 0, 0) - 0.0F) <= 1e-6F &&
                    std::abs(image.value(0, 0, 1) - 1.0F) <= 1e-6F;
    if (!ok) {
        std::fprintf(stderr,
                     "decode_image: %zu x %zu x %zu, expected 2 x 1 x 1 with values 0 and 1\n",
                     image.width, image.height, image.channels);
        return 1;
    }
    std::printf("roughscope %s: a PNG read by roughscope::photo alone (values 0 and 1)\n",
                ROUGHSCOPE_VERSION_STRING);
    return 0;
}
