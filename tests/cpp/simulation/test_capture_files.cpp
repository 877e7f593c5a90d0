// Capture files read back by independent decoders: libpng and libtiff give the written DN (and
// the float TIFF the linear signal), and Debian's LibRaw decodes the DNG to the same linear DN
// with the written black and white levels.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <libraw/libraw.h>
#include <png.h>
#include <tiffio.h>

#include "../io/test_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::simulation {
namespace {

namespace fs = std::filesystem;

Capture noisy_sphere(int bits, std::uint64_t seed = 3) {
    Scene scene;
    scene.shape = SceneShape::Sphere;
    scene.width = 37;
    scene.height = 23;
    scene.background_radiance = 0.01;
    SurfaceTruth truth;
    CameraModel camera;
    camera.bit_depth = bits;
    camera.seed = seed;
    camera.black_level_dn = bits == 8 ? 4.0 : 64.0;
    camera.gain_dn_per_e = bits == 8 ? 0.01 : 0.25;
    return render_capture(scene, {truth}, {}, camera);
}

fs::path write(const std::string& bytes, const std::string& name) {
    const fs::path dir = roughscope::testing::fresh_dir(concat("capture_", name));
    const fs::path path = dir / name;
    io::write_file_atomic(path, bytes);
    return path;
}

std::vector<std::uint16_t> read_png(const fs::path& path, int& bit_depth, int& significant) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    EXPECT_NE(f, nullptr);
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_read_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    const png_uint_32 w = png_get_image_width(png, info);
    const png_uint_32 h = png_get_image_height(png, info);
    bit_depth = png_get_bit_depth(png, info);
    png_color_8p sbit = nullptr;
    significant = png_get_sBIT(png, info, &sbit) != 0 ? sbit->gray : 0;
    png_bytepp rows = png_get_rows(png, info);
    std::vector<std::uint16_t> out;
    for (png_uint_32 r = 0; r < h; ++r)
        for (png_uint_32 c = 0; c < w; ++c)
            out.push_back(bit_depth == 8 ? rows[r][c]
                                         : static_cast<std::uint16_t>((rows[r][2 * c] << 8) |
                                                                      rows[r][2 * c + 1]));
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(f);
    return out;
}

template <class T>
std::vector<T> read_tiff(const fs::path& path, std::uint16_t& bits, std::uint16_t& format) {
    TIFF* tif = TIFFOpen(path.c_str(), "r");
    EXPECT_NE(tif, nullptr);
    std::uint32_t w = 0, h = 0;
    TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &h);
    TIFFGetField(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
    std::vector<T> out(std::size_t{w} * h);
    for (std::uint32_t r = 0; r < h; ++r)
        TIFFReadScanline(tif, out.data() + std::size_t{r} * w, r, 0);
    TIFFClose(tif);
    return out;
}

TEST(CaptureFiles, Png16ReadsBackTheDn) {
    const Capture c = noisy_sphere(14);
    int bits = 0, significant = 0;
    const auto dn = read_png(write(encode_capture_png(c), "c16.png"), bits, significant);
    EXPECT_EQ(bits, 16);
    EXPECT_EQ(significant, 14);
    EXPECT_EQ(dn, c.dn);
}

TEST(CaptureFiles, Png8ReadsBackTheDn) {
    const Capture c = noisy_sphere(8);
    int bits = 0, significant = 0;
    const auto dn = read_png(write(encode_capture_png(c), "c8.png"), bits, significant);
    EXPECT_EQ(bits, 8);
    EXPECT_EQ(dn, c.dn);
}

TEST(CaptureFiles, TiffReadsBackTheDnAndFloatTiffTheLinearSignal) {
    const Capture c = noisy_sphere(16);
    std::uint16_t bits = 0, format = 0;
    EXPECT_EQ(read_tiff<std::uint16_t>(write(encode_capture_tiff(c), "c.tiff"), bits, format),
              c.dn);
    EXPECT_EQ(bits, 16);
    EXPECT_EQ(format, SAMPLEFORMAT_UINT);
    EXPECT_EQ(read_tiff<float>(write(encode_capture_tiff_float(c), "f.tiff"), bits, format),
              c.expected_dn);
    EXPECT_EQ(bits, 32);
    EXPECT_EQ(format, SAMPLEFORMAT_IEEEFP);
}

TEST(CaptureFiles, LibRawDecodesTheDngToTheWrittenLinearDn) {
    for (int bits : {8, 12, 14, 16}) {
        SCOPED_TRACE(bits);
        const Capture c = noisy_sphere(bits, 11);
        CameraModel camera;
        camera.bit_depth = bits;
        camera.black_level_dn = bits == 8 ? 4.0 : 64.0;
        const fs::path path =
            write(encode_capture_dng(c, camera), concat("c", std::to_string(bits), ".dng"));
        LibRaw raw;
        ASSERT_EQ(raw.open_file(path.c_str()), LIBRAW_SUCCESS);
        ASSERT_EQ(raw.unpack(), LIBRAW_SUCCESS);
        EXPECT_EQ(raw.imgdata.sizes.raw_width, c.width);
        EXPECT_EQ(raw.imgdata.sizes.raw_height, c.height);
        EXPECT_TRUE(raw.imgdata.idata.dng_version != 0);
        EXPECT_EQ(raw.imgdata.color.maximum, static_cast<unsigned>(camera.white_level_dn()));
        const unsigned black = raw.imgdata.color.black + raw.imgdata.color.cblack[0];
        EXPECT_EQ(black, static_cast<unsigned>(camera.black_level_dn));
        // LibRaw 0.20 unpacks a 3-sample LinearRaw image to color4_image (4 samples a pixel, the
        // 4th unused; values as stored, the black level not subtracted).
        EXPECT_EQ(raw.imgdata.idata.colors, 3);
        EXPECT_EQ(raw.imgdata.idata.filters, 0U);
        const auto* rgb = raw.imgdata.rawdata.color4_image;
        ASSERT_NE(rgb, nullptr);
        const std::size_t pitch = raw.imgdata.sizes.raw_pitch / 8;  // pixels per row
        std::size_t mismatches = 0;
        for (std::size_t r = 0; r < c.height; ++r)
            for (std::size_t col = 0; col < c.width; ++col)
                for (int k = 0; k < 3; ++k)
                    mismatches += rgb[r * pitch + col][k] != c.dn[r * c.width + col] ? 1 : 0;
        EXPECT_EQ(mismatches, 0U);
    }
}

TEST(CaptureFiles, ARenderForAFileWritesTheBytesOfAFullRender) {
    // capture_options_for_file keeps only what the file needs (no radiance; expected_dn for the
    // float TIFF; geometry with several regions): every format's bytes equal a full render's.
    Scene scene;
    scene.shape = SceneShape::Cylinder;
    scene.width = 41;
    scene.height = 29;
    SurfaceTruth a, b;
    b.sigma_um = 2.0 * a.sigma_um;
    std::vector<std::int32_t> labels(scene.width * scene.height);
    for (std::size_t i = 0; i < labels.size(); ++i)
        labels[i] = static_cast<std::int32_t>((i % scene.width) * 2 / scene.width);
    CameraModel camera;
    camera.bit_depth = 12;
    camera.gain_dn_per_e = 0.25;
    camera.read_noise_e = 2.0;
    camera.seed = 11;
    for (const bool several : {false, true}) {
        const std::vector<SurfaceTruth> truths =
            several ? std::vector<SurfaceTruth>{a, b} : std::vector<SurfaceTruth>{a};
        const std::vector<std::int32_t> l = several ? labels : std::vector<std::int32_t>{};
        const Capture full = render_capture(scene, truths, l, camera);
        for (const CaptureFormat f : {CaptureFormat::Png, CaptureFormat::Tiff,
                                      CaptureFormat::TiffFloat, CaptureFormat::Dng}) {
            const CaptureOptions o = capture_options_for_file(f, several);
            EXPECT_FALSE(o.keep_radiance);
            EXPECT_EQ(o.keep_geometry, several);
            const Capture lean = render_capture(scene, truths, l, camera, o);
            EXPECT_TRUE(lean.radiance.empty());
            EXPECT_EQ(lean.expected_dn.empty(), f != CaptureFormat::TiffFloat);
            EXPECT_EQ(lean.label, several ? full.label : std::vector<std::int32_t>{});
            EXPECT_EQ(lean.saturated_count, full.saturated_count);
            EXPECT_EQ(lean.object_count, full.object_count);
            EXPECT_EQ(encode_capture(lean, camera, f), encode_capture(full, camera, f))
                << to_string(f) << (several ? ", two regions" : "");
        }
    }
    // Without expected_dn there is no float TIFF: an error, not an empty image.
    const Capture lean = render_capture(scene, {a}, {}, camera,
                                        capture_options_for_file(CaptureFormat::Tiff, false));
    EXPECT_THROW(encode_capture_tiff_float(lean), InvalidArgument);
}

TEST(CaptureFiles, DngRefusesANonLinearResponse) {
    Capture c = noisy_sphere(12);
    CameraModel camera;
    camera.response = Response::Srgb;
    EXPECT_THROW(encode_capture_dng(c, camera), InvalidArgument);
    c.dn.clear();
    EXPECT_THROW(encode_capture_png(c), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::simulation
