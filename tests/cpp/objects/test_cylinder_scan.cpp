// Steps 2 and 3 of the cylinder profile (objects/cylinder_steps.hpp): the band scan and the bins
// of brightness against incidence angle, against images whose brightness is a known function of
// the distance from the axis (paper §5.2: "averaging the brightness values over the vertical
// neighbors").
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cylinder_images.hpp"
#include "objects/cylinder_steps.hpp"
#include "roughscope/core/errors.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using namespace roughscope::image::detail;
using roughscope::testing::cylinder_law_image;
using roughscope::testing::lambert_law;

TEST(CylinderScan, SumsDoNotDependOnTheNumberOfThreads) {
    const CylinderAxis axis = cylinder_axis_from_line(250.0, 300.0, 0.2, 1.0, 150.0);
    const LinearImage img =
        cylinder_law_image(500, 900, axis, lambert_law(150.0, 0.8, 0.01), 0.01, 997);
    const CylinderBinning g = bin_cylinder(axis, CylinderOptions{}, img.width, img.height);
    ASSERT_GE(g.bands, 3U);
    const CylinderSums one = scan_cylinder(img, nullptr, g, {}, 1);
    for (const std::size_t threads : {2, 3}) {
        const CylinderSums many = scan_cylinder(img, nullptr, g, {}, threads);
        for (std::size_t b = 0; b < g.bins; ++b) {
            EXPECT_EQ(many.bins[b].sum, one.bins[b].sum);
            EXPECT_EQ(many.bins[b].diff2, one.bins[b].diff2);
            EXPECT_EQ(many.bins[b].count, one.bins[b].count);
        }
        EXPECT_EQ(many.sub_d, one.sub_d);
        EXPECT_EQ(many.slice_sum, one.slice_sum);
    }
}

TEST(CylinderBins, StandardErrorOfAPixelIsTheNoiseOverTheRootOfItsCount) {
    const double R = 150.0, noise = 0.02;
    const CylinderAxis axis = cylinder_axis_from_line(250.0, 400.0, 0.0, 1.0, R);
    const LinearImage img = cylinder_law_image(500, 800, axis, lambert_law(R, 0.8, 0.01), noise);
    CylinderOptions o;
    const CylinderBinning g = bin_cylinder(axis, o, img.width, img.height);
    const CylinderBins bins = profile_bins(scan_cylinder(img, nullptr, g, {}, 1), g, o, "noisy");
    for (const ProfileBin& b : bins.bins) {
        const double expected = noise / std::sqrt(static_cast<double>(b.count)) / bins.maximum;
        EXPECT_NEAR(b.stderr_pixel / expected, 1.0, 0.15) << "bin of " << b.count << " pixels";
        // Independent noise: the slices along the axis scatter as much.
        EXPECT_NEAR(b.stderr_slices / expected, 1.0, 0.35) << "bin of " << b.count << " pixels";
    }
}

TEST(CylinderBins, TooFewBinsOrNoBrightnessAreDataErrors) {
    const CylinderAxis axis = cylinder_axis_from_line(100.0, 60.0, 0.0, 1.0, 50.0);
    CylinderOptions o;
    const CylinderBinning g = bin_cylinder(axis, o, 200, 120);
    LinearImage img = cylinder_law_image(200, 120, axis, lambert_law(50.0, 0.8, 0.01));
    o.min_pixels_per_bin = 100000;
    try {
        (void)profile_bins(scan_cylinder(img, nullptr, g, {}, 1), g, o, "small.png");
        FAIL() << "no DataError";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("small.png"), std::string::npos) << e.what();
    }
    o.min_pixels_per_bin = 20;
    std::fill(img.values.begin(), img.values.end(), 0.0F);
    EXPECT_THROW((void)profile_bins(scan_cylinder(img, nullptr, g, {}, 1), g, o, "dark.png"),
                 DataError);
}

}  // namespace
