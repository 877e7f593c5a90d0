// The exact series where the capture set allows it (measure/exact_series.hpp, docs/uncertainty.md
// "Model error"), on synthetic captures rendered with the exact series of Eq. 2 (the simulation
// topic) at g = 0.2 … 30, where Eq. 17 / 19 are tens of percent off:
//  * σ known (given with its standard error, or from a specular capture) and a perturbed pair:
//    the truth inside the exact series' 95 % interval in ≥ 90 % of the runs for both
//    correlations, while the closed form's own interval misses it in many;
//  * ≥ 3 geometries, σ unknown: the joint fit's σ, T and σ/T cover the truth in ≥ 90 % of noisy
//    runs;
//  * noise-free captures: closed_form_deviation_rel is (closed − truth)/truth.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../io/test_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/serialize/measure.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;

constexpr double kLambdaUm = 0.555;

// The exact B–K brightness (the series of Eq. 2) of σ, T and a correlation at 0.555 µm.
sim::SurfaceTruth series_truth(double sigma, double T, Correlation correlation) {
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::Tabulated;
    truth.sigma_um = sigma;
    truth.T_um = T;
    truth.correlation = correlation;
    truth.tabulated = [sigma, T, correlation](const Geometry& geom) {
        ModelOptions o;
        o.regime = Regime::Series;
        const ScatteredPower p = mean_scattered_power(geom, Surface{sigma, T, correlation}, o);
        return p.diffuse * radiometric_factor(o.radiometry, geom);
    };
    return truth;
}

sim::SurfaceTruth constant_truth(double value) {
    sim::SurfaceTruth t;
    t.model = sim::BrightnessModel::Tabulated;
    t.tabulated = [value](const Geometry&) { return value; };
    return t;
}

// σ of g = σ² v_z² at the normal-view geometry of incidence θ.
double sigma_of_g(double g, double theta_deg) {
    return std::sqrt(g) /
           std::abs(scattering_vector(normal_view_geometry(deg_to_rad(theta_deg)), kLambdaUm).vz);
}

// One capture as the bench really took it.
struct Shot {
    double theta_i_deg = 30.0;
    double view_x_deg = 0.0, view_y_deg = 0.0;  // camera tilt
    double exposure_s = 1.0;
    double black_dn = 2000.0;
};

sim::CameraModel bench_camera(double peak, const Shot& shot, std::uint64_t seed, bool noise) {
    sim::CameraModel camera;
    camera.bit_depth = 16;
    camera.full_well_e = 1e6;
    camera.gain_dn_per_e = 0.05;
    camera.black_level_dn = shot.black_dn;
    camera.read_noise_e = noise ? 40.0 : 0.0;
    camera.shot_noise = noise;
    camera.electrons_per_unit_s = 0.6 * camera.full_well_e / peak;
    camera.exposure_s = shot.exposure_s;
    camera.seed = seed;
    return camera;
}

// Renders a diffuse capture of `truth` (32 × 32 16-bit TIFF); `peak` sets the camera's scale (the
// same for every capture of a set, so the exposure times compare them).
std::string render_diffuse(const fs::path& file, const sim::SurfaceTruth& truth, const Shot& shot,
                           double peak, std::uint64_t seed, bool noise = true) {
    sim::Scene scene;
    scene.width = scene.height = 32;
    scene.view = Eigen::Vector3d(std::tan(deg_to_rad(shot.view_x_deg)),
                                 std::tan(deg_to_rad(shot.view_y_deg)), 1.0)
                     .normalized();
    scene.light = sim::direction_from_angles(deg_to_rad(shot.theta_i_deg), kPi);
    sim::CaptureOptions options;
    options.keep_geometry = false;
    options.keep_radiance = false;
    options.threads = 1;
    const sim::Capture c =
        sim::render_capture(scene, {truth}, {}, bench_camera(peak, shot, seed, noise), options);
    io::write_file_atomic(file, sim::encode_capture_tiff(c));
    return file.string();
}

// A specular capture at θ (32 × 32): a disc of radius 4 px (the highlight's core) of brightness
// E_tot in a surround E_dif, with R_spec = 1 − E_dif/E_tot = exp(−g_spec) of the true σ (Eq. 12).
std::string render_specular(const fs::path& file, double sigma, double theta_deg,
                            std::uint64_t seed) {
    const double vz_spec = 4.0 * kPi * std::cos(deg_to_rad(theta_deg)) / kLambdaUm;
    const double r_spec = std::exp(-sigma * sigma * vz_spec * vz_spec);
    const double e_tot = 1.0 / (1.0 - r_spec);
    sim::Scene scene;
    scene.width = scene.height = 32;
    std::vector<std::int32_t> labels(32 * 32, 0);
    for (std::size_t r = 0; r < 32; ++r)
        for (std::size_t c = 0; c < 32; ++c) {
            const double dx = static_cast<double>(c) + 0.5 - 16.0;
            const double dy = static_cast<double>(r) + 0.5 - 16.0;
            if (dx * dx + dy * dy <= 16.0) labels[r * 32 + c] = 1;
        }
    scene.light = sim::direction_from_angles(deg_to_rad(theta_deg), kPi);
    scene.view = sim::direction_from_angles(deg_to_rad(theta_deg), 0.0);
    sim::CaptureOptions options;
    options.threads = 1;
    options.keep_geometry = false;
    options.keep_radiance = false;
    Shot shot;
    sim::CameraModel camera = bench_camera(e_tot, shot, seed, true);
    camera.full_well_e = 1e7;  // a deep well: the highlight's contrast is a few percent at most
    camera.electrons_per_unit_s = 0.6 * camera.full_well_e / e_tot;
    camera.gain_dn_per_e = 0.005;
    const sim::Capture c = sim::render_capture(scene, {constant_truth(1.0), constant_truth(e_tot)},
                                               labels, camera, options);
    io::write_file_atomic(file, sim::encode_capture_tiff(c));
    return file.string();
}

std::string diffuse_entry(const std::string& file, double theta_deg) {
    return concat(R"({"image": ")", file, R"(", "theta_i_deg": )", check::format_number(theta_deg),
                  R"(, "exposure_s": 1})");
}

bool inside(double truth, const ExactSeriesCorrelation& e) {
    return e.interval95_low && e.interval95_high && truth >= *e.interval95_low &&
           truth <= *e.interval95_high;
}

// ≥ 60 runs (30 per correlation): g at the 45° capture log-spaced over 0.2 … 30, σ/T 0.15 … 0.5,
// light angles, camera tilt, exposures and black level drawn from the declared tolerances; σ
// given with its standard error (drawn from it), or, where g ≤ 5, from a specular capture at 70°
// in every third run.
TEST(MeasureExactSeries, SigmaKnownCoversTheTruthWhereTheClosedFormDoesNot) {
    const fs::path dir = testing::fresh_dir("exact_series_coverage");
    std::mt19937_64 rng(20260601);
    std::normal_distribution<double> z(0.0, 1.0);
    const int per_correlation = 30;
    const double slopes[] = {0.15, 0.3, 0.5};
    std::uint64_t seed = 7000;
    for (const Correlation correlation : {Correlation::Gaussian, Correlation::Exponential}) {
        int covered = 0, closed_missed = 0, specular_runs = 0;
        double worst_deviation = 0.0;
        for (int run = 0; run < per_correlation; ++run) {
            const double g = 0.2 * std::pow(150.0, run / (per_correlation - 1.0));
            const double s = slopes[run % 3];
            const double sigma = sigma_of_g(g, 45.0);
            const double T = sigma / s;
            const sim::SurfaceTruth truth = series_truth(sigma, T, correlation);
            const double peak =
                std::max(sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(30.0))),
                         sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(45.0))));
            std::vector<std::string> entries;
            for (const double theta : {30.0, 45.0}) {
                Shot shot;
                shot.theta_i_deg = theta + 0.5 * z(rng);
                shot.view_x_deg = 0.5 * z(rng);
                shot.view_y_deg = 0.5 * z(rng);
                shot.exposure_s = 1.0 + 0.01 * z(rng);
                shot.black_dn = 2000.0 + 40.0 * z(rng);
                entries.push_back(
                    diffuse_entry(render_diffuse(dir / concat("d", std::to_string(theta), ".tiff"),
                                                 truth, shot, peak, ++seed),
                                  theta));
            }
            std::string sigma_keys;
            const bool specular = g <= 5.0 && run % 3 == 1;
            if (specular) {
                ++specular_runs;
                entries.insert(
                    entries.begin(),
                    concat(R"({"image": ")", render_specular(dir / "s.tiff", sigma, 70.0, ++seed),
                           R"(", "theta_i_deg": 70, "theta_s_deg": 70, )",
                           R"("role": "specular", "exposure_s": 1})"));
            } else {
                const double u_sigma = 0.03 * sigma;
                sigma_keys =
                    concat(R"("sigma_um": )", check::format_number(sigma + u_sigma * z(rng)),
                           R"(, "sigma_um_stderr": )", check::format_number(u_sigma), ", ");
            }
            std::string captures;
            for (const auto& e : entries) captures += (captures.empty() ? "" : ", ") + e;
            const MeasureResult r = measure(parse_capture_file(
                concat(
                    R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, )",
                    R"("highlight": {"core_radius_px": 3, "annulus_inner_px": 6, )",
                    R"("annulus_outer_px": 10, "centre_px": [16, 16]}, )", sigma_keys,
                    R"("correlation": ")", to_string(correlation), R"(", )",
                    R"("uncertainty": {"angle_deg": 0.5, "exposure_rel": 0.01, )",
                    R"("black_level_dn": 40, "wavelength_um": 0.001, "method": "first_order"}, )",
                    R"("captures": [)", captures, "]}"),
                (dir / "c.json").string()));
            ASSERT_TRUE(r.exact_series) << "g = " << g;
            EXPECT_EQ(r.exact_series->method, ExactSeriesMethod::SigmaKnown);
            const ExactSeriesCorrelation* e = (*r.exact_series)[correlation];
            ASSERT_NE(e, nullptr);
            if (inside(s, *e)) ++covered;
            // The closed form's own 95 % interval (the budget's; σ known, no model error in it).
            const QuantityBudget* closed = nullptr;
            for (const auto& q : r.uncertainty->quantities)
                if (q.quantity == correlation_key("sigma_over_T", correlation)) closed = &q;
            if (closed && (s < closed->result.interval95_low || s > closed->result.interval95_high))
                ++closed_missed;
            if (e->closed_form_deviation_rel)
                worst_deviation =
                    std::max(worst_deviation, std::abs(*e->closed_form_deviation_rel));
        }
        EXPECT_GE(covered, per_correlation * 9 / 10)
            << to_string(correlation) << ": " << covered << " of " << per_correlation;
        EXPECT_GE(closed_missed, per_correlation / 3)
            << to_string(correlation) << ": " << closed_missed << " of " << per_correlation;
        EXPECT_GT(specular_runs, 0);
        std::printf(
            "[ series   ] %s: truth inside the exact series' 95 %% interval in %d of %d runs "
            "(%d with σ from a specular capture); the closed form's interval misses it in %d; "
            "largest |closed − series|/series %.2f\n",
            std::string(to_string(correlation)).c_str(), covered, per_correlation, specular_runs,
            closed_missed, worst_deviation);
    }
}

// σ unknown, four geometries (θi = 20°, 35°, 50°, 65°, camera on the normal) with pixel noise and
// exposures drawn from the declared 1 %: the joint fit's 95 % intervals (σ ± 1.96 u, T, σ/T) hold
// the truth in ≥ 90 % of the runs.
// The joint fit's profile-likelihood intervals (exact_series_profile.hpp) hold σ, T and σ/T in
// ≥ 90 % of 60 noisy runs at g 0.2 … 3 (measured: 55, 55, 56), where the fit alone (its
// covariance, ± 1.96 s.e.) missed them in a third of the runs: at small g it settled in another
// minimum with a small standard error. Where σ is not determined (small g) its interval is
// open-ended and says so.
TEST(MeasureExactSeries, TheJointFitOfFourGeometriesCoversSigmaAndT) {
    const fs::path dir = testing::fresh_dir("exact_series_fit");
    std::mt19937_64 rng(77);
    std::normal_distribution<double> z(0.0, 1.0);
    const double thetas[] = {20.0, 35.0, 50.0, 65.0};
    const int runs = 60;
    int covered_sigma = 0, covered_T = 0, covered_slope = 0, with_errors = 0, undetermined = 0;
    std::uint64_t seed = 9000;
    for (int run = 0; run < runs; ++run) {
        const double g = 0.2 * std::pow(15.0, run / (runs - 1.0));  // at 50°: 0.2 … 3
        const double s = run % 2 == 0 ? 0.2 : 0.4;
        const Correlation correlation =
            run % 3 == 0 ? Correlation::Exponential : Correlation::Gaussian;
        const double sigma = sigma_of_g(g, 50.0);
        const double T = sigma / s;
        const sim::SurfaceTruth truth = series_truth(sigma, T, correlation);
        double peak = 0.0;
        for (const double t : thetas)
            peak =
                std::max(peak, sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(t))));
        std::string captures;
        for (const double t : thetas) {
            Shot shot;
            shot.theta_i_deg = t;
            shot.exposure_s = 1.0 + 0.01 * z(rng);
            captures += (captures.empty() ? "" : ", ") +
                        diffuse_entry(render_diffuse(dir / concat("d", std::to_string(t), ".tiff"),
                                                     truth, shot, peak, ++seed),
                                      t);
        }
        const MeasureResult r = measure(parse_capture_file(
            concat(R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, )",
                   R"("uncertainty": {"angle_deg": 0.01, "exposure_rel": 0.01, "black_level_dn": )",
                   R"(1}, "captures": [)", captures, "]}"),
            (dir / "c.json").string()));
        ASSERT_TRUE(r.exact_series);
        EXPECT_EQ(r.exact_series->method, ExactSeriesMethod::Fit);
        const ExactSeriesCorrelation* e = (*r.exact_series)[correlation];
        ASSERT_NE(e, nullptr);
        if (!e->sigma_um_interval95 || !e->T_um_interval95) continue;
        ++with_errors;
        const auto within = [](double truth_value, const std::array<double, 2>& interval) {
            return interval[0] <= truth_value && truth_value <= interval[1];
        };
        covered_sigma += within(sigma, *e->sigma_um_interval95) ? 1 : 0;
        covered_T += within(T, *e->T_um_interval95) ? 1 : 0;
        covered_slope += inside(s, *e) ? 1 : 0;
        undetermined += e->sigma_determined ? 0 : 1;
    }
    EXPECT_GE(with_errors, runs * 9 / 10);
    EXPECT_GE(covered_sigma, runs * 9 / 10) << covered_sigma << " of " << runs;
    EXPECT_GE(covered_T, runs * 9 / 10) << covered_T << " of " << runs;
    EXPECT_GE(covered_slope, runs * 9 / 10) << covered_slope << " of " << runs;
    std::printf(
        "[ series   ] joint fit of 4 geometries: sigma inside in %d, T in %d, sigma/T in %d of %d "
        "runs (%d with intervals, %d with sigma not determined)\n",
        covered_sigma, covered_T, covered_slope, runs, with_errors, undetermined);
}

// Noise-free captures, σ given exactly: the exact series gives the truth, and
// closed_form_deviation_rel is (closed − truth)/truth; the JSON carries it.
TEST(MeasureExactSeries, TheClosedFormDeviationIsTheClosedFormsError) {
    const fs::path dir = testing::fresh_dir("exact_series_deviation");
    std::uint64_t seed = 11000;
    for (const Correlation correlation : {Correlation::Gaussian, Correlation::Exponential}) {
        for (const double g : {0.2, 2.0, 30.0}) {
            const double s = 0.3;
            const double sigma = sigma_of_g(g, 45.0);
            const sim::SurfaceTruth truth = series_truth(sigma, sigma / s, correlation);
            const double peak =
                std::max(sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(30.0))),
                         sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(45.0))));
            std::string captures;
            for (const double t : {30.0, 45.0}) {
                Shot shot;
                shot.theta_i_deg = t;
                captures +=
                    (captures.empty() ? "" : ", ") +
                    diffuse_entry(render_diffuse(dir / concat("d", std::to_string(t), ".tiff"),
                                                 truth, shot, peak, ++seed, false),
                                  t);
            }
            const MeasureRequest request = parse_capture_file(
                concat(R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, )",
                       R"("sigma_um": )", check::format_number(sigma), R"(, "correlation": ")",
                       to_string(correlation), R"(", "captures": [)", captures, "]}"),
                (dir / "c.json").string());
            const MeasureResult r = measure(request);
            ASSERT_TRUE(r.exact_series);
            const ExactSeriesCorrelation* e = (*r.exact_series)[correlation];
            ASSERT_TRUE(e && e->sigma_over_T);
            EXPECT_NEAR(e->sigma_over_T->value, s, 2e-3 * s) << "g = " << g;
            if (!e->closed_form_sigma_over_T) {  // E1/E2 outside Eq. 16/18's range
                std::printf("[ series   ] %s, g = %.1f: no closed form\n",
                            std::string(to_string(correlation)).c_str(), g);
                continue;
            }
            ASSERT_TRUE(e->closed_form_deviation_rel);
            const double expected = (*e->closed_form_sigma_over_T - s) / s;
            EXPECT_NEAR(*e->closed_form_deviation_rel, expected, 3e-3 * (1.0 + std::abs(expected)))
                << to_string(correlation) << ", g = " << g;
            ASSERT_EQ(e->g.size(), 2u);
            EXPECT_NEAR(e->g[1], g, 1e-9 * g);
            std::printf("[ series   ] %s, g = %.1f: closed form %+.1f %% off the truth\n",
                        std::string(to_string(correlation)).c_str(), g, 100.0 * expected);
            const serialize::Json json = serialize::to_json(r, request);
            const auto& j = json["exact_series"][std::string(to_string(correlation))];
            EXPECT_TRUE(j["sigma_over_T"].is_number());
            EXPECT_TRUE(j["closed_form_deviation_rel"].is_number());
        }
    }
}

// Nothing to estimate with: σ unknown and a pair only.
TEST(MeasureExactSeries, APairWithoutSigmaHasNoExactSeries) {
    const fs::path dir = testing::fresh_dir("exact_series_none");
    const sim::SurfaceTruth truth = series_truth(0.2, 0.6, Correlation::Gaussian);
    const double peak = sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(30.0)));
    std::string captures;
    for (const double t : {30.0, 45.0}) {
        Shot shot;
        shot.theta_i_deg = t;
        captures += (captures.empty() ? "" : ", ") +
                    diffuse_entry(render_diffuse(dir / concat("d", std::to_string(t), ".tiff"),
                                                 truth, shot, peak, 5),
                                  t);
    }
    const MeasureResult r = measure(parse_capture_file(
        concat(R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, "captures": [)",
               captures, "]}"),
        (dir / "c.json").string()));
    EXPECT_FALSE(r.exact_series);
}

}  // namespace
}  // namespace roughscope::image
