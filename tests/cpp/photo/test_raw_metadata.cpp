// What a camera RAW file says of its exposure and of its data (image/read.hpp, docs/image.md
// "Camera RAW"): an exposure time or f-number the file records as 0 is unknown (LibRaw derives
// 1 s and f/1 from the APEX tags), and a lossy DNG (processed 8-bit data) carries a warning. The
// self-contained files are byte-built DNGs (image_files.hpp); the real ones are
// ../shared/data/raw (its README gives their metadata; skipped when absent).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <libraw/libraw.h>

#include "../io/shared_data.hpp"
#include "image_files.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/photo/read.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
using testing::ByteVector;
using testing::TiffEntry;

// 24 x 22 RGGB sites of a mid grey (LibRaw reads no image under 22 x 22).
ByteVector grey_dng(const std::vector<TiffEntry>& exif) {
    const std::vector<std::uint16_t> sites(24 * 22, 1000);
    return testing::bayer_dng(24, 22, sites, {64}, 4095, {{1, 1}, {1, 1}, {1, 1}}, {0, 0}, exif);
}

// As Magic Lantern writes them: ExposureTime 0/1000000, FNumber 0/10, and the APEX values
// ShutterSpeedValue 0/96 and ApertureValue 0/96.
std::vector<TiffEntry> unrecorded_exposure() {
    return {testing::rationals(33434, {{0, 1000000}}), testing::rationals(33437, {{0, 10}}),
            testing::rationals(37377, {{0, 96}}, true), testing::rationals(37378, {{0, 96}})};
}

TEST(RawMetadata, AnExposureRecordedAsZeroIsUnknownNotOneSecond) {
    const ByteVector file = grey_dng(unrecorded_exposure());
    // LibRaw itself (the fact the reader corrects): APEX Tv = 0 → 1 s, Av = 0 → f/1.
    LibRaw raw;
    ByteVector copy = file;  // LibRaw 0.20 takes a non-const buffer
    ASSERT_EQ(raw.open_buffer(copy.data(), copy.size()), LIBRAW_SUCCESS);
    EXPECT_EQ(raw.imgdata.other.shutter, 1.0F);
    EXPECT_EQ(raw.imgdata.other.aperture, 1.0F);
    const LinearImage image =
        decode_image(std::span<const std::uint8_t>(file), "unrecorded.dng", {});
    EXPECT_FALSE(image.info.exposure_s) << *image.info.exposure_s;
    EXPECT_FALSE(image.info.f_number) << *image.info.f_number;
    EXPECT_TRUE(image.info.warnings.empty());
    // A recorded exposure beside the APEX zeros is read as recorded.
    std::vector<TiffEntry> recorded = unrecorded_exposure();
    recorded[0] = testing::rationals(33434, {{1, 125}});
    recorded[1] = testing::rationals(33437, {{56, 10}});
    const ByteVector timed = grey_dng(recorded);
    const LinearImage with_time =
        decode_image(std::span<const std::uint8_t>(timed), "recorded.dng", {});
    EXPECT_NEAR(with_time.info.exposure_s.value_or(0.0), 1.0 / 125.0, 1e-9);
    EXPECT_NEAR(with_time.info.f_number.value_or(0.0), 5.6, 1e-6);
}

std::optional<fs::path> shared_raw(const std::string& name) {
    return io::find_shared(concat("data/raw/", name), testing::shared_search_starts());
}

TEST(RawMetadata, MagicLanternDngHasNoExposure) {
    const auto path = shared_raw("colorchart.dng");
    ROUGHSCOPE_NEED_SHARED(path, "data/raw/colorchart.dng");
    const LinearImage image = read_image(path->string());
    EXPECT_FALSE(image.info.exposure_s);
    EXPECT_FALSE(image.info.f_number);
    EXPECT_FALSE(image.info.iso);
    EXPECT_EQ(image.info.white_level_dn, 15000.0);  // the README's black 2056, white 15000
    EXPECT_EQ(image.info.black_level_dn, (std::vector<double>{2056.0, 2056.0, 2056.0}));
}

TEST(RawMetadata, LossyDngWarnsThatItsValuesAreProcessed) {
    const auto lossy = shared_raw("canon_eos_6d.dng");
    ROUGHSCOPE_NEED_SHARED(lossy, "data/raw/canon_eos_6d.dng");
    const LinearImage image = read_image(lossy->string());
    ASSERT_EQ(image.info.warnings.size(), 1U);
    EXPECT_NE(image.info.warnings[0].find("lossy DNG"), std::string::npos);
    EXPECT_NE(image.info.warnings[0].find("not linear sensor counts"), std::string::npos);
    // Its EXIF IFD records ExposureTime 1/60 s.
    EXPECT_NEAR(image.info.exposure_s.value_or(0.0), 1.0 / 60.0, 1e-6);
    // A real sensor RAW gets no such warning.
    const auto cr2 = shared_raw("IMG_5952.CR2");
    ROUGHSCOPE_NEED_SHARED(cr2, "data/raw/IMG_5952.CR2");
    EXPECT_TRUE(read_image(cr2->string()).info.warnings.empty());
}

}  // namespace
}  // namespace roughscope::image
