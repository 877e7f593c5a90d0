// The uncertainty budget of a measurement (measure/budget.hpp, docs/uncertainty.md) on synthetic
// captures (simulation/capture.hpp) whose setup is off from the capture file's nominal values by
// errors drawn from the declared uncertainties: the true σ/T must lie inside the stated 95 %
// interval in at least 90 % of the runs; the largest source of the budget is the one declared
// largest; first order and Monte Carlo agree where the model is near-linear; the budget's value
// is the measured value; assumed tolerances are said.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../io/test_files.hpp"
#include "../maps/map_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;
using roughscope::testing::very_rough_truth;

// The true setup of one run, and what the capture file says of it.
struct Bench {
    double theta1_deg = 30.0, theta2_deg = 45.0;  // true light zeniths
    double view_x_deg = 0.0, view_y_deg = 0.0;    // true camera tilt (in and out of the plane)
    double exposure1 = 1.0, exposure2 = 1.0;      // true exposure times, s
    double black_dn = 2000.0;                     // true black level, DN
};

constexpr double kNominalBlackDn = 2000.0;

// Renders the pair of `bench` as 16-bit TIFFs (32 × 32) and measures it with the nominal setup
// (30°, 45°, camera on the normal, 1 s, black 2000 DN) and the declared `uncertainty` object.
// (black_strip: columns 0–3 receive no light, a light trap for "black_reference".)
std::vector<std::string> render_bench(const fs::path& dir, const Bench& bench, double sigma_over_T,
                                      Correlation correlation, std::uint64_t seed,
                                      bool black_strip = false,
                                      const sim::SurfaceTruth* given = nullptr) {
    sim::Scene scene;
    scene.width = scene.height = 32;
    scene.view = Eigen::Vector3d(std::tan(deg_to_rad(bench.view_x_deg)),
                                 std::tan(deg_to_rad(bench.view_y_deg)), 1.0)
                     .normalized();
    const sim::SurfaceTruth truth = given ? *given : very_rough_truth(sigma_over_T, correlation);
    const double peak =
        std::max(sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(30.0))),
                 sim::surface_brightness(truth, normal_view_geometry(deg_to_rad(45.0))));
    sim::CaptureOptions options;
    options.keep_geometry = false;
    options.keep_radiance = false;
    options.threads = 1;
    std::vector<std::string> files;
    for (int k = 0; k < 2; ++k) {
        sim::CameraModel camera;
        camera.bit_depth = 16;
        camera.full_well_e = 1e6;
        camera.gain_dn_per_e = 0.05;
        camera.black_level_dn = bench.black_dn;
        camera.read_noise_e = 40.0;  // 2 DN: a dark region's mean has a measurable noise
        camera.electrons_per_unit_s = 0.6 * camera.full_well_e / peak;
        camera.exposure_s = k == 0 ? bench.exposure1 : bench.exposure2;
        camera.seed = seed * 2 + static_cast<std::uint64_t>(k);
        scene.light = sim::direction_from_angles(
            deg_to_rad(k == 0 ? bench.theta1_deg : bench.theta2_deg), kPi);
        sim::SurfaceTruth trap;
        trap.model = sim::BrightnessModel::Tabulated;
        trap.tabulated = [](const Geometry&) { return 0.0; };
        std::vector<std::int32_t> labels;
        if (black_strip)
            for (std::size_t i = 0; i < scene.width * scene.height; ++i)
                labels.push_back(i % scene.width < 4 ? 1 : 0);
        const sim::Capture c = sim::render_capture(scene, {truth, trap}, labels, camera, options);
        files.push_back((dir / concat("c", std::to_string(k), ".tiff")).string());
        io::write_file_atomic(files.back(), sim::encode_capture_tiff(c));
    }
    return files;
}

// The renders are the very-rough model itself (g = ∞): the declared bound on g is set so high
// that the model error of Eq. 17 (tested on its own below) is negligible, unless given.
std::string with_min_g(const std::string& uncertainty) {
    if (uncertainty.find("very_rough_min_g") != std::string::npos || uncertainty == "{}")
        return uncertainty;
    return concat(uncertainty.substr(0, uncertainty.rfind('}')),
                  uncertainty.find(':') == std::string::npos ? "" : ", ",
                  R"("very_rough_min_g": 1e6})");
}

MeasureResult measure_bench(const fs::path& dir, const Bench& bench, double sigma_over_T,
                            Correlation correlation, const std::string& uncertainty,
                            std::uint64_t seed) {
    const std::vector<std::string> files =
        render_bench(dir, bench, sigma_over_T, correlation, seed);
    const std::string text =
        concat(R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": )",
               check::format_number(kNominalBlackDn), R"(, "uncertainty": )",
               with_min_g(uncertainty), R"(, "captures": [{"image": ")", files[0],
               R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")", files[1],
               R"(", "theta_i_deg": 45, "exposure_s": 1}]})");
    return measure(parse_capture_file(text, (dir / "capture.json").string()));
}

const QuantityBudget* quantity(const MeasureResult& r, const std::string& name) {
    if (!r.uncertainty) return nullptr;
    for (const auto& q : r.uncertainty->quantities)
        if (q.quantity == name) return &q;
    return nullptr;
}

// ≥ 200 runs: angles (in and out of the plane of incidence), exposures and black level drawn
// from the declared uncertainties; the truth inside the 95 % interval in ≥ 90 % of the runs, for
// both correlations (each rendered with its own model).
TEST(MeasureBudget, TheIntervalCoversTheTruthOfAPerturbedBench) {
    const fs::path dir = testing::fresh_dir("budget_coverage");
    const double u_angle = 0.5, u_exposure = 0.01, u_black = 40.0;
    const std::string declared =
        concat(R"({"angle_deg": )", check::format_number(u_angle), R"(, "exposure_rel": )",
               check::format_number(u_exposure), R"(, "black_level_dn": )",
               check::format_number(u_black), "}");
    std::mt19937_64 rng(20261207);
    std::normal_distribution<double> z(0.0, 1.0);
    for (const Correlation correlation : {Correlation::Gaussian, Correlation::Exponential}) {
        const std::string key = correlation_key("sigma_over_T", correlation);
        const double truth = 0.3;
        int covered = 0, runs = 0;
        double width_sum = 0.0;
        for (int run = 0; run < 110; ++run) {
            Bench b;
            b.theta1_deg += u_angle * z(rng);
            b.theta2_deg += u_angle * z(rng);
            b.view_x_deg = u_angle * z(rng);
            b.view_y_deg = u_angle * z(rng);
            b.exposure1 *= 1.0 + u_exposure * z(rng);
            b.exposure2 *= 1.0 + u_exposure * z(rng);
            b.black_dn += u_black * z(rng);
            const MeasureResult r = measure_bench(dir, b, truth, correlation, declared,
                                                  static_cast<std::uint64_t>(run));
            const QuantityBudget* q = quantity(r, key);
            ASSERT_NE(q, nullptr) << key;
            ++runs;
            width_sum += q->result.interval95_high - q->result.interval95_low;
            if (truth >= q->result.interval95_low && truth <= q->result.interval95_high) ++covered;
            // Nothing assumed: every source was declared.
            EXPECT_TRUE(r.uncertainty->assumed.empty());
        }
        const double coverage = static_cast<double>(covered) / runs;
        EXPECT_GE(coverage, 0.90) << key << ": " << covered << " of " << runs;
        // Not covered by being huge: the mean interval is within a few per cent of σ/T.
        EXPECT_LT(width_sum / runs, 0.5 * truth) << key;
        std::printf(
            "[ budget   ] %s: truth inside the 95 %% interval in %d of %d runs, mean "
            "width %.4f\n",
            key.c_str(), covered, runs, width_sum / runs);
    }
}

// The control: the same bench declared ten times better than it is: the intervals no longer
// cover the truth (the coverage test above can fail).
TEST(MeasureBudget, AnUnderstatedSetupIsNotCovered) {
    const fs::path dir = testing::fresh_dir("budget_understated");
    std::mt19937_64 rng(7);
    std::normal_distribution<double> z(0.0, 1.0);
    int covered = 0;
    const int runs = 60;
    for (int run = 0; run < runs; ++run) {
        Bench b;
        b.theta1_deg += 0.5 * z(rng);
        b.theta2_deg += 0.5 * z(rng);
        b.exposure1 *= 1.0 + 0.01 * z(rng);
        b.exposure2 *= 1.0 + 0.01 * z(rng);
        b.black_dn += 40.0 * z(rng);
        const MeasureResult r =
            measure_bench(dir, b, 0.3, Correlation::Gaussian,
                          R"({"angle_deg": 0.05, "exposure_rel": 0.001, "black_level_dn": 4})",
                          static_cast<std::uint64_t>(run));
        const QuantityBudget* q = quantity(r, "sigma_over_T_gaussian");
        ASSERT_NE(q, nullptr);
        if (0.3 >= q->result.interval95_low && 0.3 <= q->result.interval95_high) ++covered;
    }
    EXPECT_LT(covered, runs * 6 / 10) << covered << " of " << runs;
}

// The largest declared source leads the budget: one tolerance made dominant at a time.
TEST(MeasureBudget, TheLargestDeclaredSourceLeadsTheBudget) {
    const fs::path dir = testing::fresh_dir("budget_largest");
    const Bench nominal;
    const struct {
        const char* declared;
        const char* leader;  // the start of the leading source's name
    } cases[] = {
        {R"({"angle_deg": 3, "exposure_rel": 0.001, "black_level_dn": 1})", "theta_i of capture"},
        {R"({"angle_deg": 0.01, "exposure_rel": 0.05, "black_level_dn": 1})",
         "exposure of capture"},
        {R"({"angle_deg": 0.01, "exposure_rel": 0.001, "black_level_dn": 400})", "black level"},
    };
    for (const auto& c : cases) {
        const MeasureResult r =
            measure_bench(dir, nominal, 0.3, Correlation::Gaussian, c.declared, 7);
        const QuantityBudget* q = quantity(r, "sigma_over_T_gaussian");
        ASSERT_NE(q, nullptr);
        ASSERT_FALSE(q->result.budget.empty());
        EXPECT_EQ(q->result.budget[0].source.rfind(c.leader, 0), 0U)
            << c.declared << ": " << q->result.budget[0].source;
        double sum = 0.0;
        for (const auto& line : q->result.budget) sum += line.fraction;
        EXPECT_NEAR(sum, 1.0, 1e-9);
    }
}

// The budget's value is the measured value; u covers at least the statistical standard error;
// Monte Carlo agrees with first order on this near-linear case (u within 10 %).
TEST(MeasureBudget, FirstOrderAndMonteCarloAgreeWhereTheModelIsNearLinear) {
    const fs::path dir = testing::fresh_dir("budget_methods");
    const Bench nominal;
    const std::string fo = R"({"angle_deg": 0.5, "exposure_rel": 0.01, "black_level_dn": 40,
                               "method": "first_order"})";
    const std::string mc = R"({"angle_deg": 0.5, "exposure_rel": 0.01, "black_level_dn": 40,
                               "method": "monte_carlo", "seed": 3})";
    const MeasureResult a = measure_bench(dir, nominal, 0.3, Correlation::Gaussian, fo, 11);
    const MeasureResult b = measure_bench(dir, nominal, 0.3, Correlation::Gaussian, mc, 11);
    ASSERT_TRUE(a.uncertainty && b.uncertainty);
    EXPECT_EQ(a.uncertainty->method, PropagationMethod::FirstOrder);
    EXPECT_EQ(b.uncertainty->method, PropagationMethod::MonteCarlo);
    for (const char* name : {"E1_over_E2", "sigma_over_T_gaussian", "sigma_over_T_exponential"}) {
        const QuantityBudget* qa = quantity(a, name);
        const QuantityBudget* qb = quantity(b, name);
        ASSERT_TRUE(qa && qb) << name;
        EXPECT_NEAR(qb->result.uncertainty, qa->result.uncertainty, 0.1 * qa->result.uncertainty)
            << name;
        EXPECT_GE(qb->result.trials, 20000U);
    }
    ASSERT_TRUE(a.slope_gaussian && a.E1_over_E2);
    EXPECT_DOUBLE_EQ(quantity(a, "sigma_over_T_gaussian")->result.value,
                     a.slope_gaussian->sigma_over_T->value);
    EXPECT_DOUBLE_EQ(quantity(a, "E1_over_E2")->result.value, a.E1_over_E2->value);
    EXPECT_GT(quantity(a, "sigma_over_T_gaussian")->result.uncertainty,
              a.slope_gaussian->sigma_over_T->std_error);
}

// Near the end of Eq. 16's valid range (σ/T large: E1/E2 close to its limit C) the model is not
// near-linear: Auto takes Monte Carlo and its interval is wider than first order's.
TEST(MeasureBudget, MonteCarloIsWiderNearTheEndOfTheRatiosRange) {
    const fs::path dir = testing::fresh_dir("budget_range_end");
    const Bench nominal;
    const std::string fo = R"({"angle_deg": 1, "exposure_rel": 0.01, "black_level_dn": 40,
                               "method": "first_order"})";
    const std::string au = R"({"angle_deg": 1, "exposure_rel": 0.01, "black_level_dn": 40})";
    const MeasureResult a = measure_bench(dir, nominal, 2.0, Correlation::Gaussian, fo, 5);
    const MeasureResult b = measure_bench(dir, nominal, 2.0, Correlation::Gaussian, au, 5);
    const QuantityBudget* qa = quantity(a, "sigma_over_T_gaussian");
    const QuantityBudget* qb = quantity(b, "sigma_over_T_gaussian");
    ASSERT_TRUE(qa && qb);
    EXPECT_EQ(b.uncertainty->method, PropagationMethod::MonteCarlo) << b.uncertainty->method_reason;
    EXPECT_GT(qb->result.interval95_high - qb->result.interval95_low,
              qa->result.interval95_high - qa->result.interval95_low);
}

// A 16-bit TIFF of a mirror sphere (circle (128, 128, 100) in a 256 × 256 image, camera along +z)
// lit from `light`: a 2° lobe about the mirror direction of the view plus a dim diffuse term.
std::string write_mirror_sphere(const fs::path& file, const Eigen::Vector3d& light) {
    sim::Capture c;
    c.width = c.height = 256;
    c.bit_depth = 16;
    c.dn.assign(c.width * c.height, 200);
    c.saturated.assign(c.width * c.height, 0);
    const double cx = 128.0, cy = 128.0, r = 100.0, lobe = deg_to_rad(2.0);
    for (std::size_t y = 0; y < c.height; ++y)
        for (std::size_t x = 0; x < c.width; ++x) {
            const double nx = (x + 0.5 - cx) / r, ny = -(y + 0.5 - cy) / r;
            const double rho2 = nx * nx + ny * ny;
            if (rho2 >= 1.0) continue;
            const Eigen::Vector3d n(nx, ny, std::sqrt(1.0 - rho2));
            const Eigen::Vector3d mirror = 2.0 * n.z() * n - Eigen::Vector3d::UnitZ();
            const double angle = std::acos(std::clamp(mirror.dot(light), -1.0, 1.0));
            const double value = 0.9 * std::exp(-angle * angle / (2 * lobe * lobe)) +
                                 0.02 * std::max(0.0, n.dot(light));
            c.dn[y * c.width + x] = static_cast<std::uint16_t>(std::lround(200 + 60000 * value));
        }
    io::write_file_atomic(file, sim::encode_capture_tiff(c));
    return file.string();
}

// Lights set off the nominal 30°/45° and calibrated from a mirror sphere: σ/T as if the light
// were known, and the calibration's uncertainty in the budget; the nominal angles are worse.
TEST(MeasureBudget, AMirrorSphereGivesTheLight) {
    const fs::path dir = testing::fresh_dir("budget_mirror_sphere");
    Bench b;
    b.theta1_deg = 31.0;
    b.theta2_deg = 44.0;
    const std::vector<std::string> files = render_bench(dir, b, 0.3, Correlation::Gaussian, 9);
    std::string spheres[2];
    for (int k = 0; k < 2; ++k)
        spheres[k] = write_mirror_sphere(
            dir / concat("sphere", std::to_string(k), ".tiff"),
            sim::direction_from_angles(deg_to_rad(k == 0 ? b.theta1_deg : b.theta2_deg), kPi));
    const std::string head =
        R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, "uncertainty": {"angle_deg": 0.5, "exposure_rel": 0.001, "black_level_dn": 1, "very_rough_min_g": 1e6}, "captures": [)";
    const auto capture = [&](int k, const std::string& light) {
        return concat(R"({"image": ")", files[k], R"(", "exposure_s": 1, )", light, "}");
    };
    const auto sphere_light = [&](int k) {
        return concat(R"("light": {"mirror_sphere": {"image": ")", spheres[k],
                      R"(", "circle": [128, 128, 100], "circle_uncertainty_px": 0.05}})");
    };
    const MeasureResult calibrated = measure(parse_capture_file(
        concat(head, capture(0, sphere_light(0)), ", ", capture(1, sphere_light(1)), "]}"),
        (dir / "c.json").string()));
    const MeasureResult nominal =
        measure(parse_capture_file(concat(head, capture(0, R"("theta_i_deg": 30)"), ", ",
                                          capture(1, R"("theta_i_deg": 45)"), "]}"),
                                   (dir / "c.json").string()));
    const double with_sphere = calibrated.slope_gaussian->sigma_over_T->value;
    const double with_nominal = nominal.slope_gaussian->sigma_over_T->value;
    EXPECT_NEAR(rad_to_deg(calibrated.captures[0].spec.geometry.theta_i_rad), 31.0, 0.1);
    EXPECT_NEAR(rad_to_deg(calibrated.captures[1].spec.geometry.theta_i_rad), 44.0, 0.1);
    EXPECT_NEAR(with_sphere, 0.3, 0.003);
    EXPECT_GT(std::abs(with_nominal - 0.3), 3.0 * std::abs(with_sphere - 0.3));
    // The calibration's uncertainty (well below the declared 0.5°) is the light's in the budget.
    const QuantityBudget* q = quantity(calibrated, "sigma_over_T_gaussian");
    ASSERT_NE(q, nullptr);
    bool found = false;
    for (const auto& line : q->result.budget)
        if (line.source == "theta_i of capture 1") {
            found = true;
            EXPECT_LT(rad_to_deg(line.u_input), 0.3);
            EXPECT_GT(line.u_input, 0.0);
        }
    EXPECT_TRUE(found);
    // The camera must look along the sample's normal for a light in the camera frame.
    EXPECT_THROW(measure(parse_capture_file(
                     concat(head, capture(0, sphere_light(0) + R"(, "view": [0.1, 0, 1])"), ", ",
                            capture(1, sphere_light(1)), "]}"),
                     (dir / "c.json").string())),
                 DataError);
}

// A black level 1500 DN above the declared one: without a black reference σ/T is biased beyond
// its interval; with one (a light trap in the frame) it is measured, subtracted and its standard
// error is each capture's own source in the budget.
TEST(MeasureBudget, ABlackReferenceMeasuresTheBlackLevel) {
    const fs::path dir = testing::fresh_dir("budget_black_reference");
    Bench b;
    b.black_dn = kNominalBlackDn + 1500.0;
    const std::vector<std::string> files =
        render_bench(dir, b, 0.3, Correlation::Gaussian, 4, true);
    const auto run = [&](const std::string& extra) {
        return measure(parse_capture_file(
            concat(
                R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, )", extra,
                R"("uncertainty": {"angle_deg": 0.1, "exposure_rel": 0.001, "black_level_dn": 5, "very_rough_min_g": 1e6},
                      "captures": [{"image": ")",
                files[0], R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")", files[1],
                R"(", "theta_i_deg": 45, "exposure_s": 1}]})"),
            (dir / "c.json").string()));
    };
    const MeasureResult plain = run("");
    const MeasureResult with = run(R"("black_reference": {"rect": [0, 0, 4, 32]}, )");
    const QuantityBudget* p = quantity(plain, "sigma_over_T_gaussian");
    const QuantityBudget* w = quantity(with, "sigma_over_T_gaussian");
    ASSERT_TRUE(p && w);
    EXPECT_FALSE(0.3 >= p->result.interval95_low && 0.3 <= p->result.interval95_high)
        << p->result.value;
    EXPECT_TRUE(0.3 >= w->result.interval95_low && 0.3 <= w->result.interval95_high)
        << w->result.value << " ± " << w->result.uncertainty;
    ASSERT_TRUE(with.captures[0].black_reference);
    // 1500 DN above the declared black: 1500/(65535 − 2000) on the linear scale.
    EXPECT_NEAR(with.captures[0].black_reference->mean, 1500.0 / (65535.0 - 2000.0), 2e-4);
    bool own = false, shared = false;
    for (const auto& line : w->result.budget) {
        own = own || line.source == "black reference of capture 1";
        shared = shared || line.source.rfind("black level", 0) == 0;
    }
    EXPECT_TRUE(own);
    EXPECT_FALSE(shared);
}

// The exact B–K brightness (the series of Eq. 2, Gaussian) of σ and T at 0.555 µm.
sim::SurfaceTruth exact_sigma_T(double sigma, double T) {
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::Tabulated;
    truth.sigma_um = sigma;
    truth.T_um = T;
    truth.tabulated = [sigma, T](const Geometry& geom) {
        ModelOptions o;
        o.regime = Regime::Series;
        const ScatteredPower p =
            mean_scattered_power(geom, Surface{sigma, T, Correlation::Gaussian}, o);
        return p.diffuse * radiometric_factor(o.radiometry, geom);
    };
    return truth;
}

// T given σ on a perturbed bench: a slightly rough surface (g < 0.1, Eq. 15's regime) whose σ is
// given with its standard error, the light angles, camera tilt, exposures and black level drawn
// from the declared uncertainties: the true T inside T_um's 95 % interval in ≥ 90 % of the runs.
TEST(MeasureBudget, TheIntervalOfTGivenSigmaCoversTheTruth) {
    const fs::path dir = testing::fresh_dir("budget_T");
    const double sigma = 0.0105, T = 0.5, u_sigma = 0.0004;
    std::mt19937_64 rng(31);
    std::normal_distribution<double> z(0.0, 1.0);
    int covered = 0;
    const int runs = 60;
    for (int run = 0; run < runs; ++run) {
        Bench b;
        b.theta1_deg += 0.5 * z(rng);
        b.theta2_deg += 0.5 * z(rng);
        b.view_x_deg = 0.5 * z(rng);
        b.view_y_deg = 0.5 * z(rng);
        b.exposure1 *= 1.0 + 0.01 * z(rng);
        b.exposure2 *= 1.0 + 0.01 * z(rng);
        b.black_dn += 40.0 * z(rng);
        const double sigma_declared = sigma + u_sigma * z(rng);  // σ from elsewhere, ± u
        const sim::SurfaceTruth truth = exact_sigma_T(sigma, T);
        const auto files = render_bench(dir, b, sigma / T, Correlation::Gaussian,
                                        static_cast<std::uint64_t>(run) + 500, false, &truth);
        const MeasureResult r = measure(parse_capture_file(
            concat(
                R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, "sigma_um": )",
                check::format_number(sigma_declared), R"(, "sigma_um_stderr": )",
                check::format_number(u_sigma),
                R"(, "uncertainty": {"angle_deg": 0.5, "exposure_rel": 0.01, "black_level_dn": 40, "wavelength_um": 0.001},
                      "captures": [{"image": ")",
                files[0], R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")", files[1],
                R"(", "theta_i_deg": 45, "exposure_s": 1}]})"),
            (dir / "c.json").string()));
        const QuantityBudget* q = quantity(r, "T_um");
        ASSERT_NE(q, nullptr);
        if (T >= q->result.interval95_low && T <= q->result.interval95_high) ++covered;
    }
    EXPECT_GE(covered, runs * 9 / 10) << covered << " of " << runs;
    std::printf("[ budget   ] T given sigma: truth inside the 95 %% interval in %d of %d runs\n",
                covered, runs);
}

// The exact B–K brightness (the series of Eq. 2, Gaussian) of σ/T = s at g = σ²v_z² (v_z at
// 45°, the smaller of the pair's).
sim::SurfaceTruth exact_truth(double s, double g) {
    const double vz = scattering_vector(normal_view_geometry(deg_to_rad(45.0)), 0.555).vz;
    const double sigma = std::sqrt(g) / std::abs(vz);
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::Tabulated;
    truth.sigma_um = sigma;
    truth.T_um = sigma / s;
    truth.tabulated = [sigma, s](const Geometry& geom) {
        ModelOptions o;
        o.regime = Regime::Series;
        const ScatteredPower p =
            mean_scattered_power(geom, Surface{sigma, sigma / s, Correlation::Gaussian}, o);
        return p.diffuse * radiometric_factor(o.radiometry, geom);
    };
    return truth;
}

// Model error: surfaces of the exact series at g = 10 … 100 (very rough, but not the limit Eq. 17
// is exact in), σ unknown: with the default bound g ≥ 10 the Gaussian σ/T's interval holds the
// truth in ≥ 90 % of the cases; without the model error (bound 10⁶) it does not at g ≈ 10.
TEST(MeasureBudget, TheModelErrorOfTheVeryRoughLimitIsCovered) {
    const fs::path dir = testing::fresh_dir("budget_model_error");
    const std::string declared =
        R"({"angle_deg": 0.05, "exposure_rel": 0.001, "black_level_dn": 2)";
    int covered = 0, runs = 0, covered_without = 0, runs_without = 0;
    std::uint64_t seed = 100;
    for (const double s : {0.15, 0.3, 0.6}) {
        for (const double g : {10.0, 13.0, 20.0, 40.0, 100.0}) {
            const sim::SurfaceTruth truth = exact_truth(s, g);
            const auto files =
                render_bench(dir, Bench{}, s, Correlation::Gaussian, ++seed, false, &truth);
            const auto run = [&](const std::string& uncertainty) {
                return measure(parse_capture_file(
                    concat(R"({"roi": {"rect": [4, 4, 24, 24]}, "black_level_dn": 2000, )",
                           R"("uncertainty": )", uncertainty, R"(, "captures": [{"image": ")",
                           files[0], R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")",
                           files[1], R"(", "theta_i_deg": 45, "exposure_s": 1}]})"),
                    (dir / "c.json").string()));
            };
            const auto inside = [s](const MeasureResult& r) {
                const QuantityBudget* q = quantity(r, "sigma_over_T_gaussian");
                return q && s >= q->result.interval95_low && s <= q->result.interval95_high;
            };
            const MeasureResult r = run(declared + "}");
            ++runs;
            covered += inside(r) ? 1 : 0;
            bool has_model = false;
            for (const auto& line : quantity(r, "sigma_over_T_gaussian")->result.budget)
                has_model = has_model || line.source.rfind("model: Eq. 17", 0) == 0;
            EXPECT_TRUE(has_model);
            if (g <= 13.0) {
                ++runs_without;
                covered_without += inside(run(declared + R"(, "very_rough_min_g": 1e6})")) ? 1 : 0;
            }
        }
    }
    EXPECT_GE(covered, runs * 9 / 10) << covered << " of " << runs;
    EXPECT_LT(covered_without, runs_without / 2) << covered_without << " of " << runs_without;
    std::printf(
        "[ budget   ] model error: truth inside in %d of %d runs (without the model "
        "error, at g ≤ 13: %d of %d)\n",
        covered, runs, covered_without, runs_without);
}

// Without declared tolerances the defaults are used and the result says so.
TEST(MeasureBudget, AssumedTolerancesAreSaid) {
    const fs::path dir = testing::fresh_dir("budget_assumed");
    const MeasureResult r = measure_bench(dir, Bench{}, 0.3, Correlation::Gaussian, "{}", 2);
    ASSERT_TRUE(r.uncertainty);
    EXPECT_FALSE(r.uncertainty->assumed.empty());
    bool said = false;
    for (const auto& w : r.warnings)
        said = said || w.find("assumed tolerances") != std::string::npos;
    EXPECT_TRUE(said);
    EXPECT_THROW(measure_bench(dir, Bench{}, 0.3, Correlation::Gaussian, R"({"angle_deg": -1})", 2),
                 DataError);
    EXPECT_THROW(measure_bench(dir, Bench{}, 0.3, Correlation::Gaussian, R"({"angles": 1})", 2),
                 DataError);
}

}  // namespace
}  // namespace roughscope::image
