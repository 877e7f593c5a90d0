// Brightness profiles across rough cylinders (image/cylinder.hpp, paper §5.2, Fig. 8) against
// synthetic captures of known σ/T (simulation/capture.hpp) and the retro-reflection closed forms
// (scattering/retro.hpp, Eq. 7, 9, 10).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <stdlib.h>

#include "object_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/scattering/retro.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using roughscope::testing::camera_for;
using roughscope::testing::linear_from_capture;
using roughscope::testing::linear_from_radiance;
using roughscope::testing::very_rough_truth;
namespace sim = roughscope::simulation;

constexpr std::size_t kSize = 160;  // R = 64 px

sim::Scene cylinder_scene(const Eigen::Vector3d& light) {
    sim::Scene scene;
    scene.shape = sim::SceneShape::Cylinder;
    scene.width = kSize;
    scene.height = kSize;
    scene.pixel_size_um = 1.0;
    scene.light = light;
    return scene;
}

// The true axis of cylinder_scene: vertical through the image centre, R = 0.4 · 160.
CylinderAxis true_axis() { return cylinder_axis_from_line(80.0, 80.0, 0.0, 1.0, 64.0); }

sim::Capture render(const sim::Scene& scene, const sim::SurfaceTruth& truth,
                    const sim::CameraModel& camera, bool geometry = false) {
    sim::CaptureOptions co;
    co.keep_geometry = geometry;
    co.threads = 1;
    return sim::render_capture(scene, {truth}, {}, camera, co);
}

// A noisy capture whose brightest pixel fills 60 % of the full well.
LinearImage noisy_capture(const sim::Scene& scene, const sim::SurfaceTruth& truth, int bits,
                          std::uint64_t seed) {
    const double e_max =
        roughscope::testing::max_radiance(render(scene, truth, camera_for(bits, 1, 0.5, 1)));
    const sim::CameraModel camera = camera_for(bits, e_max, 0.6, seed);
    return linear_from_capture(render(scene, truth, camera), camera);
}

TEST(CylinderProfile, BinIncidenceAnglesMatchTheRenderersPerPixelAngles) {
    for (const double light_deg : {0.0, 30.0}) {
        const Eigen::Vector3d L = sim::direction_from_angles(deg_to_rad(light_deg), kPi);
        const sim::Scene scene = cylinder_scene(L);
        const sim::SurfaceTruth truth = very_rough_truth(1.0, Correlation::Gaussian);
        const sim::Capture cap = render(scene, truth, camera_for(14, 1, 0.5, 1, false), true);
        CylinderOptions o;
        o.light = L;
        o.axis = true_axis();
        const CylinderProfile p = measure_cylinder_profile(linear_from_radiance(cap), nullptr, o);
        ASSERT_GE(p.bins.size(), 20U);
        // Per bin: the renderer's own θi averaged over the pixels whose normal angle α about the
        // axis (from the renderer's normal) falls in the bin.
        for (const ProfileBin& b : p.bins) {
            const double lo = std::floor(b.alpha_rad / p.bin_width_rad) * p.bin_width_rad;
            double sum = 0;
            std::size_t n = 0;
            for (std::size_t i = 0; i < cap.normal.size() / 3; ++i) {
                const double nx = cap.normal[3 * i];
                if (std::isnan(nx) || std::isnan(cap.theta_i_rad[i])) continue;
                const double alpha = std::asin(std::clamp(nx, -1.0, 1.0));
                if (alpha < lo || alpha >= lo + p.bin_width_rad) continue;
                sum += cap.theta_i_rad[i];
                ++n;
            }
            ASSERT_GT(n, 0U);
            EXPECT_NEAR(b.theta_i_rad, sum / static_cast<double>(n), 0.1 * p.bin_width_rad)
                << "light " << light_deg << " deg, bin at " << rad_to_deg(b.alpha_rad) << " deg";
            if (light_deg == 0.0) {  // L = V: retro geometry
                EXPECT_NEAR(b.geometry.theta_s_rad, b.theta_i_rad, 1e-9);
                EXPECT_NEAR(b.geometry.phi_s_rad, kPi, 1e-6);
            }
        }
    }
}

TEST(CylinderProfile, NoiseFreeVhGaussianCaptureEqualsEq9) {
    for (const double s : {0.3, 0.6, 1.0}) {
        const sim::Scene scene = cylinder_scene(Eigen::Vector3d(0, 0, 1));
        const sim::Capture cap =
            render(scene, very_rough_truth(s, Correlation::Gaussian), camera_for(14, 1, 0.5, 1));
        CylinderOptions o;
        o.axis = true_axis();
        o.sigma_over_T = s;
        const CylinderProfile p = measure_cylinder_profile(linear_from_radiance(cap), nullptr, o);
        const ProfileModelCurve& vh = p.curve(ProfileModel::VhGaussian);
        double worst = 0;
        for (std::size_t b = 0; b < p.bins.size(); ++b)
            worst = std::max(worst, std::abs(vh.prediction[b] - p.bins[b].brightness));
        EXPECT_LT(worst, 1e-3) << "sigma/T " << s;
        EXPECT_FALSE(vh.departure_bin.has_value());
        // The fit recovers σ/T (no noise: the model is exact).
        ASSERT_TRUE(p.gaussian_fit.sigma_over_T.has_value());
        EXPECT_NEAR(*p.gaussian_fit.sigma_over_T / s, 1.0, 1e-4);
        EXPECT_NEAR(*p.theta_K_rad, caron_theta_K_rad(s), 1e-12);
    }
}

TEST(CylinderProfile, GeneralFormsAtRetroGeometryAreEq7Eq9Eq10) {
    for (const double s : {0.2, 0.5, 1.3}) {
        double r7 = 0, r9 = 0, r10 = 0;
        for (int k = 0; k <= 85; k += 5) {
            const Geometry g = retro_geometry(deg_to_rad(k));
            if (retro_beckmann_gaussian_very_rough(g.theta_i_rad, s) < 1e-250) continue;
            const double a7 = profile_model_brightness(ProfileModel::BkGaussian, g, s) /
                              retro_beckmann_gaussian_very_rough(g.theta_i_rad, s);
            const double a9 = profile_model_brightness(ProfileModel::VhGaussian, g, s) /
                              retro_vh_gaussian_very_rough(g.theta_i_rad, s);
            const double a10 = profile_model_brightness(ProfileModel::VhExponential, g, s) /
                               retro_vh_exponential_very_rough(g.theta_i_rad, s);
            if (k == 0) {
                r7 = a7;
                r9 = a9;
                r10 = a10;
            }
            EXPECT_NEAR(a7 / r7, 1.0, 1e-12) << k;
            EXPECT_NEAR(a9 / r9, 1.0, 1e-12) << k;
            EXPECT_NEAR(a10 / r10, 1.0, 1e-12) << k;
        }
        EXPECT_NEAR(profile_model_brightness(ProfileModel::Lambert, retro_geometry(0.7), s),
                    std::cos(0.7), 1e-15);
    }
}

TEST(CylinderProfile, FittedSigmaOverTCoverage) {
    struct Case {
        double s;
        Correlation c;
        int bits;
    };
    std::vector<Case> cases;
    const double sigmas[] = {0.4, 0.7, 1.2};
    const int bits[] = {8, 12, 14, 16};
    for (const double s : sigmas)
        for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential})
            for (const int b : bits) cases.push_back({s, c, b});
    const sim::Scene scene = cylinder_scene(Eigen::Vector3d(0, 0, 1));
    int inside = 0, total = 0;
    std::uint64_t seed = 100;
    for (const Case& c : cases)
        for (int rep = 0; rep < 2; ++rep) {
            const LinearImage img =
                noisy_capture(scene, very_rough_truth(c.s, c.c), c.bits, seed++);
            CylinderOptions o;
            o.axis = true_axis();
            const CylinderProfile p = measure_cylinder_profile(img, nullptr, o);
            const ProfileFit& f = c.c == Correlation::Gaussian ? p.gaussian_fit : p.exponential_fit;
            ASSERT_TRUE(f.sigma_over_T.has_value()) << f.message;
            ASSERT_GT(f.sigma_over_T_stderr, 0.0);
            ++total;
            const bool ok = std::abs(*f.sigma_over_T - c.s) <= 2.0 * f.sigma_over_T_stderr;
            inside += ok;
            if (!ok)
                std::printf("  outside: sigma/T %.2f %s %d bit: %.5f +/- %.5f\n", c.s,
                            c.c == Correlation::Gaussian ? "gaussian" : "exponential", c.bits,
                            *f.sigma_over_T, f.sigma_over_T_stderr);
        }
    const double fraction = static_cast<double>(inside) / total;
    std::printf("cylinder coverage: %d of %d trials (%.1f %%) within the reported 2 sigma\n",
                inside, total, 100.0 * fraction);
    EXPECT_GE(total, 40);
    EXPECT_GE(fraction, 0.9);
}

TEST(CylinderProfile, DepartureAngleOfADataSetThatLeavesEq9At46Degrees) {
    const double s = 0.8, edge = deg_to_rad(46.0);
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::Tabulated;
    truth.tabulated = [&](const Geometry& g) {
        const double e = very_rough_brightness(g, s, Correlation::Gaussian);
        return g.theta_i_rad < edge ? e : 0.7 * e;
    };
    const sim::Scene scene = cylinder_scene(Eigen::Vector3d(0, 0, 1));
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const LinearImage img = noisy_capture(scene, truth, 14, seed);
        for (const bool given : {true, false}) {
            CylinderOptions o;
            o.axis = true_axis();
            if (given)
                o.sigma_over_T = s;
            else
                o.fit_max_theta_i_deg = 40.0;  // fit where the data follow Eq. 9
            const CylinderProfile p = measure_cylinder_profile(img, nullptr, o);
            const ProfileModelCurve& vh = p.curve(ProfileModel::VhGaussian);
            ASSERT_TRUE(vh.departure_theta_i_rad.has_value());
            EXPECT_NEAR(*vh.departure_theta_i_rad, edge, p.bin_width_rad)
                << "departure at " << rad_to_deg(*vh.departure_theta_i_rad) << " deg";
            ASSERT_TRUE(p.theta_K_rad.has_value());
            EXPECT_NEAR(*p.theta_K_rad, caron_theta_K_rad(*vh.sigma_over_T), 1e-12);
            // Lambert leaves these data far earlier (the V–H lobe is not cos θi).
            const ProfileModelCurve& lam = p.curve(ProfileModel::Lambert);
            ASSERT_TRUE(lam.departure_theta_i_rad.has_value());
            EXPECT_LT(*lam.departure_theta_i_rad, edge - 3 * p.bin_width_rad);
        }
    }
}

TEST(CylinderProfile, DetectedAxisOnALambertCylinderGivesCosine) {
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    const LinearImage img = noisy_capture(cylinder_scene(Eigen::Vector3d(0, 0, 1)), lambert, 14, 9);
    const CylinderProfile p = measure_cylinder_profile(img, nullptr, CylinderOptions{});
    EXPECT_TRUE(p.axis.detected);
    EXPECT_NEAR(p.axis.radius_px, 64.0, 0.2);
    const ProfileModelCurve& lam = p.curve(ProfileModel::Lambert);
    EXPECT_LT(lam.rms_difference, 5e-3);
    EXPECT_FALSE(lam.departure_bin.has_value());
    // The left half and both halves see the same cosine.
    CylinderOptions left;
    left.half = CylinderHalf::Left;
    EXPECT_LT(
        measure_cylinder_profile(img, nullptr, left).curve(ProfileModel::Lambert).rms_difference,
        5e-3);
    CylinderOptions both;
    both.half = CylinderHalf::Both;
    const CylinderProfile pb = measure_cylinder_profile(img, nullptr, both);
    EXPECT_GT(pb.bins.size(), p.bins.size() + 10);
    // A region mask keeps only its rows.
    std::vector<std::uint8_t> mask(img.pixel_count(), 0);
    for (std::size_t i = 0; i < 40 * kSize; ++i) mask[i] = 1;
    const CylinderProfile pm = measure_cylinder_profile(img, &mask, CylinderOptions{});
    EXPECT_LT(pm.pixels_used, p.pixels_used / 3);
    for (const auto& w : p.warnings)
        EXPECT_EQ(w.find("inside the true limb"), std::string::npos) << w;
}

// A very rough cylinder lit from the camera has a dark limb: the detected radius is short and a
// warning says so (the given axis has no such warning).
TEST(CylinderProfile, DetectedAxisOnADarkLimbWarns) {
    const LinearImage img = noisy_capture(cylinder_scene(Eigen::Vector3d(0, 0, 1)),
                                          very_rough_truth(0.5, Correlation::Gaussian), 14, 11);
    const CylinderProfile p = measure_cylinder_profile(img, nullptr, CylinderOptions{});
    EXPECT_TRUE(p.axis.detected);
    EXPECT_LT(p.axis.radius_px, 63.0);
    const auto warned = [](const CylinderProfile& q) {
        return std::any_of(q.warnings.begin(), q.warnings.end(), [](const std::string& w) {
            return w.find("inside the true limb") != std::string::npos;
        });
    };
    EXPECT_TRUE(warned(p));
    CylinderOptions given;
    given.axis = true_axis();
    EXPECT_FALSE(warned(measure_cylinder_profile(img, nullptr, given)));
}

TEST(CylinderProfile, BinsBeyondTheMemoryLimitAreRefusedBeforeAllocating) {
    // 1e-6 degree bins on a 160-pixel image: 9e7 bins of the normal angle, each with its sums
    // and its slices along the axis — about 180 GB of accumulators. Refused with the estimate
    // (core/memory.hpp) instead of a bad_alloc from deep inside; 0.5 degree bins are measured.
    ::setenv("ROUGHSCOPE_MEMORY_LIMIT_GB", "1", 1);
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    const LinearImage img = noisy_capture(cylinder_scene(Eigen::Vector3d(0, 0, 1)), lambert, 12, 2);
    CylinderOptions o;
    o.axis = true_axis();
    o.bin_width_deg = 1e-6;
    std::string message = "no error";
    try {
        (void)measure_cylinder_profile(img, nullptr, o);
    } catch (const InvalidArgument& e) {
        message = e.what();
    }
    o.bin_width_deg = 0.5;
    EXPECT_NO_THROW((void)measure_cylinder_profile(img, nullptr, o));
    ::unsetenv("ROUGHSCOPE_MEMORY_LIMIT_GB");
    EXPECT_NE(message.find("cylinder bin_width_deg = 1e-06 ("), std::string::npos) << message;
    EXPECT_NE(message.find("GB of memory, above the limit of 1 GB"), std::string::npos) << message;
    EXPECT_NE(message.find("give a wider bin_width_deg"), std::string::npos) << message;
}

TEST(CylinderProfile, BadInputIsAnError) {
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    const LinearImage img = noisy_capture(cylinder_scene(Eigen::Vector3d(0, 0, 1)), lambert, 12, 2);
    auto with = [](auto change) {
        CylinderOptions o;
        change(o);
        return o;
    };
    EXPECT_THROW(measure_cylinder_profile(img, nullptr, with([](CylinderOptions& o) {
                                              o.light = {0, 1, 0};
                                          })),
                 InvalidArgument);  // light on the horizon
    EXPECT_THROW(measure_cylinder_profile(img, nullptr, with([](CylinderOptions& o) {
                                              o.light = {0, 0, -1};
                                          })),
                 InvalidArgument);  // light below it
    EXPECT_THROW(measure_cylinder_profile(img, nullptr, with([](CylinderOptions& o) {
                                              o.view = {0, 0, 2};
                                          })),
                 InvalidArgument);  // not a unit vector
    EXPECT_THROW(measure_cylinder_profile(img, nullptr,
                                          with([](CylinderOptions& o) { o.bin_width_deg = 0.0; })),
                 InvalidArgument);
    EXPECT_THROW(measure_cylinder_profile(img, nullptr,
                                          with([](CylinderOptions& o) { o.bin_width_deg = 50.0; })),
                 InvalidArgument);
    EXPECT_THROW(measure_cylinder_profile(img, nullptr,
                                          with([](CylinderOptions& o) { o.limb_fraction = 0.0; })),
                 InvalidArgument);
    EXPECT_THROW(measure_cylinder_profile(img, nullptr,
                                          with([](CylinderOptions& o) { o.sigma_over_T = -1.0; })),
                 InvalidArgument);
    EXPECT_THROW(measure_cylinder_profile(
                     img, nullptr, with([](CylinderOptions& o) { o.fit_max_theta_i_deg = 90; })),
                 InvalidArgument);
    EXPECT_THROW(measure_cylinder_profile(img, nullptr,
                                          with([](CylinderOptions& o) { o.departure_bins = 0; })),
                 InvalidArgument);
    EXPECT_THROW(measure_cylinder_profile(img, nullptr, with([](CylinderOptions& o) {
                                              o.min_pixels_per_bin = 1000000;
                                          })),
                 DataError);  // no bin keeps enough pixels
    const std::vector<std::uint8_t> short_mask(10, 1);
    EXPECT_THROW(measure_cylinder_profile(img, &short_mask, {}), InvalidArgument);
    LinearImage dark = img;
    std::fill(dark.values.begin(), dark.values.end(), 0.0F);
    EXPECT_THROW(measure_cylinder_profile(dark, nullptr, {}), DataError);  // no object
    EXPECT_THROW(parse_cylinder_half("middle"), InvalidArgument);
    EXPECT_THROW(parse_profile_model("phong"), InvalidArgument);
    EXPECT_EQ(parse_profile_model("vh_exponential"), ProfileModel::VhExponential);
}

// A textured Lambert cylinder lit from the camera whose axis is tilted by `tilt_rad` from the
// image vertical, with a few flagged pixels: deterministic, noisy, several bands of rows.
LinearImage tilted_cylinder(std::size_t w, std::size_t h, double tilt_rad, double radius) {
    LinearImage img;
    img.width = w;
    img.height = h;
    img.channels = 1;
    img.values.assign(w * h, 0.0F);
    img.flags.assign(w * h, 0);
    const double ax = std::sin(tilt_rad), ay = std::cos(tilt_rad);
    for (std::size_t r = 0; r < h; ++r)
        for (std::size_t c = 0; c < w; ++c) {
            const double x = static_cast<double>(c) + 0.5 - 0.5 * static_cast<double>(w);
            const double y = static_cast<double>(r) + 0.5 - 0.5 * static_cast<double>(h);
            const double s = (x * ay - y * ax) / radius;
            const double texture = 0.02 * static_cast<double>((r * 7 + c * 13) % 17) / 17.0;
            img.values[r * w + c] = static_cast<float>(
                0.01 + (s * s < 1.0 ? 0.8 * std::sqrt(1.0 - s * s) : 0.0) + texture);
            if ((r * 31 + c * 17) % 997 == 0) img.flags[r * w + c] = kPixelSaturated;
        }
    return img;
}

TEST(CylinderProfile, ResultDoesNotDependOnTheNumberOfThreads) {
    const LinearImage img = tilted_cylinder(700, 900, deg_to_rad(30.0), 200.0);
    std::vector<std::uint8_t> region(img.pixel_count(), 1);
    for (std::size_t i = 0; i < region.size(); i += 11) region[i] = 0;
    for (const bool detected : {true, false})
        for (const CylinderHalf half : {CylinderHalf::Right, CylinderHalf::Both}) {
            CylinderOptions o;
            o.half = half;
            if (!detected)
                o.axis = cylinder_axis_from_line(350.0, 450.0, std::sin(deg_to_rad(30.0)),
                                                 std::cos(deg_to_rad(30.0)), 200.0);
            o.threads = 1;
            const CylinderProfile one = measure_cylinder_profile(img, &region, o);
            ASSERT_GE(one.bins.size(), 20U);
            EXPECT_GT(one.pixels_flagged, 0U);
            for (const std::size_t threads : {2, 3}) {
                o.threads = threads;
                const CylinderProfile many = measure_cylinder_profile(img, &region, o);
                ASSERT_EQ(many.bins.size(), one.bins.size());
                EXPECT_EQ(many.axis.radius_px, one.axis.radius_px);
                EXPECT_EQ(many.pixels_used, one.pixels_used);
                EXPECT_EQ(many.pixels_flagged, one.pixels_flagged);
                EXPECT_EQ(many.maximum, one.maximum);
                for (std::size_t b = 0; b < one.bins.size(); ++b) {
                    const ProfileBin &x = many.bins[b], &y = one.bins[b];
                    EXPECT_EQ(x.across_px, y.across_px);
                    EXPECT_EQ(x.brightness, y.brightness);
                    EXPECT_EQ(x.stderr_slices, y.stderr_slices);
                    EXPECT_EQ(x.stderr_pixel, y.stderr_pixel);
                    EXPECT_EQ(x.count, y.count);
                    EXPECT_EQ(x.flagged, y.flagged);
                    EXPECT_EQ(x.slices, y.slices);
                }
                for (std::size_t m = 0; m < one.models.size(); ++m)
                    EXPECT_EQ(many.models[m].prediction, one.models[m].prediction);
                EXPECT_EQ(many.gaussian_fit.sigma_over_T, one.gaussian_fit.sigma_over_T);
                EXPECT_EQ(many.exponential_fit.sigma_over_T, one.exponential_fit.sigma_over_T);
            }
        }
}

// No region: each row's segments are summed in the pass's segment paths (classification at the
// segments' ends only; along a steep axis half-sub-bins kept per column, along a shallow one
// slices kept per column). A region of all ones sends the same pixels through the per-pixel
// path: the profiles must agree to rounding, for axes near the columns and near the rows, tilted
// (slices and half-sub-bins change along a row and down a column), both signs of the tilt, grey
// and RGB, every half, detected and given axes, with flagged pixels.
TEST(CylinderProfile, SegmentsSummedWithoutPerPixelTestsAgreeWithThePerPixelPath) {
    for (const double tilt_deg : {0.0, 3.0, 30.0, -41.0, 90.0, 87.0, 60.0, -50.0})
        for (const bool rgb : {false, true}) {
            LinearImage img = tilted_cylinder(640, 800, deg_to_rad(tilt_deg), 180.0);
            if (rgb) {
                const std::vector<float> grey(img.values.begin(), img.values.end());
                img.channels = 3;
                img.values.resize(3 * grey.size());
                for (std::size_t i = 0; i < grey.size(); ++i) {
                    img.values[grey.size() + i] = 1.25F * grey[i];
                    img.values[2 * grey.size() + i] = 0.5F * grey[i] + 0.01F;
                }
            }
            const std::vector<std::uint8_t> everywhere(img.pixel_count(), 1);
            for (const bool detected : {true, false})
                for (const CylinderHalf half :
                     {CylinderHalf::Right, CylinderHalf::Left, CylinderHalf::Both}) {
                    SCOPED_TRACE(::testing::Message()
                                 << "tilt " << tilt_deg << " rgb " << rgb << " detected "
                                 << detected << " half " << to_string(half));
                    CylinderOptions o;
                    o.half = half;
                    if (!detected)
                        o.axis =
                            cylinder_axis_from_line(320.0, 400.0, std::sin(deg_to_rad(tilt_deg)),
                                                    std::cos(deg_to_rad(tilt_deg)), 180.0);
                    const CylinderProfile fast = measure_cylinder_profile(img, nullptr, o);
                    const CylinderProfile each = measure_cylinder_profile(img, &everywhere, o);
                    EXPECT_EQ(fast.pixels_used, each.pixels_used);
                    EXPECT_EQ(fast.pixels_flagged, each.pixels_flagged);
                    EXPECT_GT(fast.pixels_flagged, 0U);
                    ASSERT_EQ(fast.bins.size(), each.bins.size());
                    ASSERT_GE(fast.bins.size(), 20U);
                    // Bins in order of α (bins at ±α of both halves have the same θi to rounding,
                    // and the profile's order of such a pair follows that rounding).
                    const auto by_alpha = [](std::vector<ProfileBin> bins) {
                        std::sort(bins.begin(), bins.end(),
                                  [](const ProfileBin& p, const ProfileBin& q) {
                                      return p.alpha_rad < q.alpha_rad;
                                  });
                        return bins;
                    };
                    const std::vector<ProfileBin> fast_bins = by_alpha(fast.bins),
                                                  each_bins = by_alpha(each.bins);
                    for (std::size_t b = 0; b < fast.bins.size(); ++b) {
                        const ProfileBin &x = fast_bins[b], &y = each_bins[b];
                        EXPECT_EQ(x.count, y.count);
                        EXPECT_EQ(x.flagged, y.flagged);
                        EXPECT_EQ(x.slices, y.slices);
                        EXPECT_NEAR(x.across_px, y.across_px, 1e-12 * std::abs(y.across_px));
                        EXPECT_NEAR(x.brightness, y.brightness, 1e-12);
                        EXPECT_NEAR(x.stderr_slices, y.stderr_slices, 1e-9 * y.stderr_slices);
                        EXPECT_NEAR(x.stderr_pixel, y.stderr_pixel, 1e-9 * y.stderr_pixel);
                        EXPECT_NEAR(x.theta_i_rad, y.theta_i_rad, 1e-12);
                    }
                    ASSERT_TRUE(fast.gaussian_fit.sigma_over_T && each.gaussian_fit.sigma_over_T);
                    EXPECT_NEAR(*fast.gaussian_fit.sigma_over_T, *each.gaussian_fit.sigma_over_T,
                                1e-7 * *each.gaussian_fit.sigma_over_T);
                    // The fast path's sums do not depend on the number of threads either.
                    o.threads = 3;
                    const CylinderProfile three = measure_cylinder_profile(img, nullptr, o);
                    ASSERT_EQ(three.bins.size(), fast.bins.size());
                    for (std::size_t b = 0; b < fast.bins.size(); ++b) {
                        EXPECT_EQ(three.bins[b].brightness, fast.bins[b].brightness);
                        EXPECT_EQ(three.bins[b].across_px, fast.bins[b].across_px);
                        EXPECT_EQ(three.bins[b].stderr_pixel, fast.bins[b].stderr_pixel);
                    }
                }
        }
}

}  // namespace
