// Roughness maps (image/maps.hpp) against synthetic captures of known roughness
// (simulation::render_capture) and against the scalar estimators of estimation.hpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "map_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image {
namespace {

using roughscope::testing::LitPair;
using roughscope::testing::render_lit_pair;
using roughscope::testing::very_rough_truth;
namespace sim = roughscope::simulation;

const double kTheta1 = deg_to_rad(30.0);
constexpr std::array<MapInstructionSet, 2> kInstructionSets{MapInstructionSet::Baseline,
                                                            MapInstructionSet::Best};
const double kTheta2 = deg_to_rad(45.0);

std::vector<MapCapture> flat_captures(const LitPair& p) {
    std::vector<MapCapture> c(2);
    c[0].image = &p.a;
    c[0].name = "lit at 30°";
    c[0].geometry = normal_view_geometry(kTheta1);
    c[1].image = &p.b;
    c[1].name = "lit at 45°";
    c[1].geometry = normal_view_geometry(kTheta2);
    return c;
}

sim::Scene plane(std::size_t w, std::size_t h) {
    sim::Scene s;
    s.width = w;
    s.height = h;
    return s;
}

// Three vertical strips of 128 px: σ/T = 0.1 (slightly), 1 (moderately), 5 (very rough).
constexpr std::array<double, 3> kStripTruth{0.1, 1.0, 5.0};
std::vector<std::int32_t> strip_labels(std::size_t w, std::size_t h, std::ptrdiff_t shift = 0) {
    std::vector<std::int32_t> labels(w * h);
    for (std::size_t r = 0; r < h; ++r)
        for (std::size_t x = 0; x < w; ++x) {
            const auto xs = std::clamp<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(x) - shift, 0,
                                                       static_cast<std::ptrdiff_t>(w) - 1);
            labels[r * w + x] = static_cast<std::int32_t>(static_cast<std::size_t>(xs) / 128);
        }
    return labels;
}
std::vector<sim::SurfaceTruth> strip_truths() {
    return {very_rough_truth(kStripTruth[0]), very_rough_truth(kStripTruth[1]),
            very_rough_truth(kStripTruth[2])};
}

TEST(RoughnessMap, ThreeRegionsOneClassEach) {
    const std::size_t W = 384, H = 192;
    const auto labels = strip_labels(W, H);
    const LitPair p =
        render_lit_pair(plane(W, H), strip_truths(), labels, labels, kTheta1, kTheta2, 11);
    MapOptions o;
    o.window_px = 16;
    o.region_labels = labels;
    o.region_names = {"slight", "moderate", "very"};
    const RoughnessMap map = roughness_map(flat_captures(p), o);
    ASSERT_EQ(map.width, 24u);
    ASSERT_EQ(map.height, 12u);
    ASSERT_TRUE(map.registration.has_value());
    EXPECT_LT(map.registration->magnitude_px, 0.5);
    // Tiles farther than one window from a region border (strip columns 1..6 of each 8).
    for (std::size_t k = 0; k < 3; ++k) {
        std::size_t right = 0, total = 0;
        for (std::size_t ty = 0; ty < map.height; ++ty)
            for (std::size_t tx = 8 * k + 1; tx < 8 * k + 7; ++tx) {
                if (k == 0 && tx == 1) continue;  // no border on the image side: keep symmetric
                ++total;
                if (map.roughness_class[ty * map.width + tx] == k) ++right;
            }
        const double fraction = static_cast<double>(right) / static_cast<double>(total);
        std::printf("region %zu (σ/T = %g): %zu/%zu tiles in the right class (%.1f %%)\n", k,
                    kStripTruth[k], right, total, 100.0 * fraction);
        EXPECT_GE(fraction, 0.95) << "region " << k;
        const RegionMapStatistics& s = map.regions[k];
        ASSERT_TRUE(s.mean_sigma_over_T_gaussian.has_value());
        const Estimate m = *s.mean_sigma_over_T_gaussian;
        std::printf("region %s: mean σ/T = %.5f ± %.5f (truth %g, %zu tiles, z = %.2f)\n",
                    s.name.c_str(), m.value, m.std_error, kStripTruth[k], s.count,
                    (m.value - kStripTruth[k]) / m.std_error);
        EXPECT_LT(std::abs(m.value - kStripTruth[k]), 2.0 * m.std_error) << s.name;
        EXPECT_EQ(s.class_counts[k],
                  *std::max_element(s.class_counts.begin(), s.class_counts.end()));
    }
    // Summaries hold no NaN but the standard error of a class of one cell (unknown).
    for (const auto& c : map.classes) {
        EXPECT_TRUE(std::isfinite(c.fraction));
        if (c.mean_sigma_over_T) {
            EXPECT_TRUE(std::isfinite(c.mean_sigma_over_T->value));
            EXPECT_TRUE(std::isfinite(c.mean_sigma_over_T->std_error) || c.count < 2);
        }
    }
    EXPECT_EQ(map.valid + map.missing + map.no_solution, map.width * map.height);
}

// Tile means computed here, pixel by pixel, and the scalar estimator on them.
TEST(RoughnessMap, NoiseFreeTilesEqualTheScalarEstimator) {
    const std::size_t W = 96, H = 64;
    std::vector<std::int32_t> halves(W * H);
    for (std::size_t i = 0; i < W * H; ++i) halves[i] = (i % W) < W / 2 ? 0 : 1;
    const std::vector<sim::SurfaceTruth> truths{very_rough_truth(0.4), very_rough_truth(2.0)};
    const LitPair p = render_lit_pair(plane(W, H), truths, halves, halves, kTheta1, kTheta2, 3,
                                      /*noise=*/false);
    for (const std::size_t window : {std::size_t{1}, std::size_t{8}}) {
        MapOptions o;
        o.window_px = window;
        o.check_registration = false;
        o.both_correlations = true;
        const RoughnessMap map = roughness_map(flat_captures(p), o);
        double worst = 0.0;
        for (const std::size_t ty : {std::size_t{0}, map.height / 2, map.height - 1})
            for (const std::size_t tx : {std::size_t{0}, map.width / 3, map.width - 1}) {
                double s1 = 0, s2 = 0;
                for (std::size_t r = ty * window; r < std::min(H, (ty + 1) * window); ++r)
                    for (std::size_t x = tx * window; x < std::min(W, (tx + 1) * window); ++x) {
                        s1 += p.a.values[r * W + x];
                        s2 += p.b.values[r * W + x];
                    }
                for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
                    SlopeInput in;
                    in.E1_over_E2 = s1 / s2;
                    in.geom1 = normal_view_geometry(kTheta1);
                    in.geom2 = normal_view_geometry(kTheta2);
                    in.correlation = c;
                    const double expected = estimate_slope(in).sigma_over_T->value;
                    const float got = (c == Correlation::Gaussian
                                           ? map.sigma_over_T_gaussian
                                           : map.sigma_over_T_exponential)[ty * map.width + tx];
                    worst = std::max(worst, std::abs(got - expected) / expected);
                }
            }
        std::printf("window %zu: largest relative difference from estimate_slope %.2e\n", window,
                    worst);
        EXPECT_LT(worst, 1e-6);  // float layers: 6e-8 rounding
    }
}

// The table against Eq. 17 / 19 over σ/T in [0.01, 100] (ratios from Eq. 16 / 18 via the
// solver-free closed forms), and against the two-geometry solver for an oblique view.
TEST(RatioInverseTable, MatchesTheClosedFormsAndTheSolver) {
    const Geometry g1 = normal_view_geometry(kTheta1), g2 = normal_view_geometry(kTheta2);
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const RatioInverseTable table = RatioInverseTable::sigma_over_T(g1, g2, c);
        double worst = 0.0, worst_derivative = 0.0;
        for (int k = 0; k <= 4000; ++k) {
            const double s = std::pow(10.0, -2.0 + 4.0 * k / 4000.0);
            // The model's ratio at s (Eq. 16 / 18) from the very-rough brightness itself.
            const double ratio = model_ratio_very_rough(g1, g2, s, c);
            if (!(ratio > 0.0) || !std::isfinite(ratio)) continue;
            SlopeInput in;
            in.E1_over_E2 = ratio;
            in.geom1 = g1;
            in.geom2 = g2;
            in.correlation = c;
            in.noise = {0.01, 0.0};
            const RoughnessEstimate e = estimate_slope(in);
            const auto v = table.lookup(std::log(ratio));
            ASSERT_TRUE(v.has_value()) << s;
            worst = std::max(worst, std::abs(v->x - e.sigma_over_T->value) / e.sigma_over_T->value);
            // sd from the table's slope equals estimation's analytic propagation.
            const double sd = std::abs(v->dx_dlog_ratio) * 0.01;
            worst_derivative = std::max(worst_derivative, std::abs(sd - e.sigma_over_T->std_error) /
                                                              e.sigma_over_T->std_error);
        }
        std::printf("%s: table vs Eq. 17/19: largest relative error %.2e (slope %.2e)\n",
                    std::string(to_string(c)).c_str(), worst, worst_derivative);
        EXPECT_LT(worst, 1e-6);
        EXPECT_LT(worst_derivative, 1e-5);
        // Outside the model's range: no value.
        const RatioRange range = table.ratio_range();
        EXPECT_FALSE(table.lookup(std::log(range.lower) - 0.1).has_value());
        EXPECT_FALSE(table.lookup(std::nan("")).has_value());
    }
    // Oblique view: the table of the model ratio against the solver.
    const Geometry o1 = make_geometry(kTheta1, deg_to_rad(20.0), 0.3);
    const Geometry o2 = make_geometry(kTheta2, deg_to_rad(20.0), 0.3);
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const RatioInverseTable table = RatioInverseTable::sigma_over_T(o1, o2, c);
        double worst = 0.0;
        for (int k = 0; k <= 200; ++k) {
            const double s = std::pow(10.0, -1.0 + 2.5 * k / 200.0);
            const double ratio = model_ratio_very_rough(o1, o2, s, c);
            const double solved = sigma_over_T_two_geometries(ratio, o1, o2, c);
            const auto v = table.lookup(std::log(ratio));
            ASSERT_TRUE(v.has_value());
            worst = std::max(worst, std::abs(v->x - solved) / solved);
        }
        std::printf("%s oblique: table vs solver %.2e\n", std::string(to_string(c)).c_str(), worst);
        EXPECT_LT(worst, 1e-6);
    }
}

// The table holds estimation.hpp's forward ratio, not a derivation of its own: at every node
// ln(E1/E2) is the logarithm of model_ratio_very_rough (Eq. 16 / 18 at normal view) bit for bit,
// and the look-up's slope there the derivative of Eq. 17 / 19 (d_sigma_over_T_*_d_log_ratio).
TEST(RatioInverseTable, NodesAreTheEstimationTopicsRatio) {
    const Geometry g1 = normal_view_geometry(kTheta1), g2 = normal_view_geometry(kTheta2);
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const RatioInverseTable table = RatioInverseTable::sigma_over_T(g1, g2, c);
        const auto x = table.node_x();
        const auto y = table.node_log_ratio();
        ASSERT_EQ(x.size(), y.size());
        ASSERT_GT(x.size(), 3000U);  // of 4097: σ/T from ~1e-2 (a ratio within double) to 1e4
        double worst_slope = 0.0;
        for (std::size_t j = 0; j < x.size(); ++j) {
            const double ratio = model_ratio_very_rough(g1, g2, x[j], c);
            ASSERT_EQ(y[j], std::log(ratio)) << to_string(c) << " node " << j;
            const auto v = table.lookup(y[j]);
            ASSERT_TRUE(v.has_value()) << j;
            EXPECT_NEAR(v->x, x[j], 1e-14 * x[j]) << j;
            const double d = d_sigma_over_T_d_log_ratio(c, ratio, kTheta1, kTheta2);
            worst_slope = std::max(worst_slope, std::abs(v->dx_dlog_ratio - d) / std::abs(d));
        }
        EXPECT_LT(worst_slope, 1e-12) << to_string(c);
    }
}

// The look-up's interval comes from an index of buckets uniform in ln(E1/E2): ratios in random
// order over six decades of σ/T (dense and sparse parts of the table) and the table's own nodes
// give back σ/T, whatever the previous look-up.
TEST(RatioInverseTable, LookUpsInAnyOrderFindTheirInterval) {
    const Geometry g1 = normal_view_geometry(kTheta1), g2 = normal_view_geometry(kTheta2);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(std::log(1e-3), std::log(1e3));
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const RatioInverseTable table = RatioInverseTable::sigma_over_T(g1, g2, c);
        std::size_t hint = 0, looked_up = 0;
        double worst = 0.0;
        for (int k = 0; k < 20000; ++k) {
            // Every fourth a node of the table (x_j = 1e-4 · 1e8^(j/4096)).
            const double s =
                k % 4 == 0 ? 1e-4 * std::pow(1e8, static_cast<double>(1024 + rng() % 2049) / 4096.0)
                           : std::exp(u(rng));
            const double ratio = model_ratio_very_rough(g1, g2, s, c);
            // Beyond double's range, or within the last step of the nodes before it (the nodes
            // are where the model ratio is a finite double, NodesAreTheEstimationTopicsRatio).
            const RatioRange range = table.ratio_range();
            if (!(ratio > 0.0) || !std::isfinite(ratio) || (ratio > range.upper && ratio > 1e300) ||
                (ratio < range.lower && ratio < 1e-300))
                continue;
            const auto v = table.lookup(std::log(ratio), hint);
            ASSERT_TRUE(v.has_value()) << s;
            worst = std::max(worst, std::abs(v->x - s) / s);
            ++looked_up;
        }
        EXPECT_GT(looked_up, 15000U);
        EXPECT_LT(worst, 1e-7) << to_string(c);
        // The index resolves the crowded ends (y − y_0 ∝ (σ/T)^−2 spans 16 decades over the
        // table): no bucket meets more than a few intervals (a bucket uniform in y met ~3000).
        EXPECT_LE(table.max_intervals_per_bucket(), 3U) << to_string(c);
    }
    // The same for tables of the two-geometry model and of T given σ.
    const Geometry o1 = make_geometry(kTheta1, deg_to_rad(20.0), 0.3);
    const Geometry o2 = make_geometry(kTheta2, deg_to_rad(20.0), 0.3);
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        EXPECT_LE(RatioInverseTable::sigma_over_T(o1, o2, c).max_intervals_per_bucket(), 3U);
        EXPECT_LE(RatioInverseTable::correlation_length(g1, g2, 0.05, c).max_intervals_per_bucket(),
                  3U);
    }
}

// find_ratio (the ratio's bits select a bin, no logarithm) against find at ln(ratio), over ratios
// spread log-uniformly in the distance to the table's anchor — the bins, the ends of the table
// and beyond it (the fallback) — for tables of Eq. 16/18 (both orders of the angles), of the
// two-geometry model and of T given σ.
TEST(RatioInverseTable, RatioBinsEqualTheLookUpAtTheLogRatio) {
    const Geometry g1 = normal_view_geometry(kTheta1), g2 = normal_view_geometry(kTheta2);
    const Geometry o1 = make_geometry(kTheta1, deg_to_rad(20.0), 0.3);
    const Geometry o2 = make_geometry(kTheta2, deg_to_rad(20.0), 0.3);
    struct Case {
        std::string name;
        RatioInverseTable table;
    };
    std::vector<Case> cases;
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const std::string n(to_string(c));
        cases.push_back({n + " 30/45", RatioInverseTable::sigma_over_T(g1, g2, c)});
        cases.push_back({n + " 45/30", RatioInverseTable::sigma_over_T(g2, g1, c)});
        cases.push_back({n + " oblique", RatioInverseTable::sigma_over_T(o1, o2, c)});
        cases.push_back({n + " T given σ", RatioInverseTable::correlation_length(g1, g2, 0.05, c)});
    }
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> log2_distance(-60.0, 90.0);
    for (const Case& k : cases) {
        const RatioRange range = k.table.ratio_range();
        std::size_t hint = 0, both = 0, neither = 0;
        double worst = 0.0, worst_slope = 0.0;
        for (int i = 0; i < 40000; ++i) {
            // A ratio at 2^d from either end of the table, inside or outside it.
            const double d = std::exp2(log2_distance(rng));
            const double end = i % 2 == 0 ? range.lower : range.upper;
            const double ratio = i % 4 < 2 ? end * (1.0 + d) : end * (1.0 - std::min(d, 0.999));
            RatioInverseTable::Value a, b;
            const bool fa = k.table.find_ratio(ratio, a, hint);
            const bool fb = k.table.find(std::log(ratio), b, hint);
            ASSERT_EQ(fa, fb) << k.name << " ratio " << ratio;
            if (!fa) {
                ++neither;
                continue;
            }
            ++both;
            // Beyond what the rounding of the ratio alone moves x by (ill-conditioned near the
            // anchor, whatever the method).
            const double rounding = 8.0 * std::numeric_limits<double>::epsilon() *
                                    (1.0 + std::abs(std::log(ratio))) * std::abs(b.dx_dlog_ratio);
            worst = std::max(worst, std::max(0.0, std::abs(a.x - b.x) - rounding) / b.x);
            // The slope where that rounding is negligible (the slope's is larger still).
            if (rounding < 1e-10 * b.x)
                worst_slope = std::max(worst_slope, std::abs(a.dx_dlog_ratio - b.dx_dlog_ratio) /
                                                        std::abs(b.dx_dlog_ratio));
        }
        std::printf(
            "%s: %zu ratio bins used; %zu ratios inside, %zu outside; largest relative "
            "difference from find(ln ratio) %.2e, slope %.2e\n",
            k.name.c_str(), k.table.ratio_bins_used(), both, neither, worst, worst_slope);
        EXPECT_GT(both, 5000U) << k.name;
        EXPECT_GT(neither, 5000U) << k.name;
        EXPECT_LT(worst, 1e-8) << k.name;
        EXPECT_LT(worst_slope, 1e-4) << k.name;
    }
    // Eq. 16/18 at normal view: the bins cover every ratio of σ/T in [0.03, 1e3] (Gaussian) and
    // [0.15, 1e3] (exponential) — no fallback. (Towards σ/T → 0 the exponential's ratio ends at
    // (a2/a1)^(3/2) C, with σ/T ∝ √(distance to it): a square root no cubic follows, so those
    // last bins go to find.)
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const RatioInverseTable table = RatioInverseTable::sigma_over_T(g1, g2, c);
        EXPECT_GT(table.ratio_bins_used(), 2000U) << to_string(c);
        for (double s = c == Correlation::Gaussian ? 0.03 : 0.15; s <= 1e3; s *= 1.01) {
            const double ratio = model_ratio_very_rough(g1, g2, s, c);
            RatioInverseTable::Value v;
            std::size_t hint = 1u << 30;  // untouched by the bins
            ASSERT_TRUE(table.find_ratio(ratio, v, hint)) << s;
            EXPECT_EQ(hint, 1u << 30) << to_string(c) << " σ/T " << s << " went to find";
            EXPECT_NEAR(v.x, s, 1e-7 * s);
        }
    }
    // find_ratio_bins (the row's loop, the processor's best build or the baseline's) gives
    // find_ratio's numbers bit for bit where a bin is used, and NaN with `true` (a ratio for find)
    // where none is.
    for (const Case& k : cases) {
        std::vector<double> ratios;
        const RatioRange range = k.table.ratio_range();
        for (int i = 0; i < 2000; ++i) {
            const double d = std::exp2(log2_distance(rng));
            ratios.push_back((i % 2 == 0 ? range.lower : range.upper) *
                             (i % 4 < 2 ? 1.0 + d : 1.0 - std::min(d, 0.999)));
        }
        ratios.push_back(std::nan(""));
        for (const MapInstructionSet isa : kInstructionSets) {
            const MapInstructionSet before = limit_map_instruction_set(isa);
            std::vector<double> x(ratios.size()), slope(ratios.size());
            const bool pending =
                k.table.find_ratio_bins(ratios.size(), ratios.data(), x.data(), slope.data());
            limit_map_instruction_set(before);
            bool missed = false;
            for (std::size_t i = 0; i < ratios.size(); ++i) {
                RatioInverseTable::Value v;
                std::size_t hint = std::size_t{1} << 30;
                const bool found = k.table.find_ratio(ratios[i], v, hint);
                if (found && hint == std::size_t{1} << 30) {  // from a bin
                    ASSERT_EQ(x[i], v.x) << k.name << " " << ratios[i];
                    ASSERT_EQ(slope[i], v.dx_dlog_ratio) << k.name << " " << ratios[i];
                } else {
                    ASSERT_TRUE(std::isnan(x[i]) && std::isnan(slope[i])) << k.name;
                    missed = missed || !std::isnan(ratios[i]);
                }
            }
            EXPECT_EQ(pending, missed) << k.name;
            EXPECT_TRUE(missed) << k.name;
        }
    }
    // No ratio, no value.
    const RatioInverseTable table = RatioInverseTable::sigma_over_T(g1, g2, Correlation::Gaussian);
    RatioInverseTable::Value v;
    std::size_t hint = 0;
    for (const double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()})
        EXPECT_FALSE(table.find_ratio(bad, v, hint)) << bad;
}

TEST(RatioInverseTable, BadInput) {
    const Geometry g = normal_view_geometry(kTheta1);
    EXPECT_THROW(RatioInverseTable::sigma_over_T(g, g, Correlation::Gaussian), InvalidArgument);
    RatioInverseTableOptions t;
    t.nodes = 2;
    EXPECT_THROW(RatioInverseTable::sigma_over_T(g, normal_view_geometry(kTheta2),
                                                 Correlation::Gaussian, {}, t),
                 InvalidArgument);
    t = {};
    t.lower = 2.0;
    t.upper = 1.0;
    EXPECT_THROW(RatioInverseTable::sigma_over_T(g, normal_view_geometry(kTheta2),
                                                 Correlation::Gaussian, {}, t),
                 InvalidArgument);
}

// z = (estimate − truth)/stderr over many tiles (and pixels) of a uniform sample, for each
// correlation (a surface of that correlation).
TEST(RoughnessMap, UncertaintyIsCalibrated) {
    const std::size_t W = 256, H = 256;
    const double truth = 1.0;
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const LitPair p = render_lit_pair(plane(W, H), {very_rough_truth(truth, c)}, {}, {},
                                          kTheta1, kTheta2, 21);
        for (const std::size_t window : {std::size_t{1}, std::size_t{8}}) {
            MapOptions o;
            o.window_px = window;
            o.correlation = c;  // (its layers only)
            const RoughnessMap map = roughness_map(flat_captures(p), o);
            const auto& v = c == Correlation::Gaussian ? map.sigma_over_T_gaussian
                                                       : map.sigma_over_T_exponential;
            const auto& se = c == Correlation::Gaussian ? map.sigma_over_T_gaussian_stderr
                                                        : map.sigma_over_T_exponential_stderr;
            double sum = 0, sum2 = 0;
            std::size_t n = 0;
            for (std::size_t i = 0; i < v.size(); ++i) {
                if (!std::isfinite(v[i])) continue;
                const double z = (v[i] - truth) / se[i];
                sum += z;
                sum2 += z * z;
                ++n;
            }
            const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
            std::printf("window %zu %s: %zu z-scores, mean %.3f, sd %.3f\n", window,
                        std::string(to_string(c)).c_str(), n, mean, sd);
            EXPECT_GT(n, v.size() * 9 / 10);
            EXPECT_GE(sd, 0.8);
            EXPECT_LE(sd, 1.25);
            EXPECT_LT(std::abs(mean), 0.2);
        }
    }
}

// Per pixel, every layer against its definition (docs/maps.md) computed here pixel by pixel:
// the used pixels of the clipped 5 × 5 neighbourhood, their means, variances and covariance,
// var(ln E1/E2) = v1/m1² + v2/m2² − 2 c12/(m1 m2), the tables at ln(x1/x2). A noisy pair with
// flagged pixels, a patch whose ratio no model produces, more rows than the column sums'
// restart (64), on one and on three threads.
TEST(RoughnessMap, PixelMapEqualsItsDefinition) {
    const std::size_t W = 57, H = 150;
    LitPair p = render_lit_pair(plane(W, H), {very_rough_truth(0.8)}, {}, {}, kTheta1, kTheta2, 5);
    std::mt19937_64 rng(3);
    for (int i = 0; i < 300; ++i) p.a.flags[rng() % (W * H)] = kPixelSaturated;
    for (int i = 0; i < 300; ++i) p.b.flags[rng() % (W * H)] = kPixelSaturated;
    // Rows 20–29 flagged but for every third pixel of every other row: neighbourhoods of 2 to 6
    // used pixels, either side of the 3 a pixel needs.
    for (std::size_t r = 20; r < 30; ++r)
        for (std::size_t x = 0; x < W; ++x)
            if (r % 2 == 1 || x % 3 != 0) p.a.flags[r * W + x] = kPixelSaturated;
    const RatioRange range = ratio_range_gaussian(kTheta1, kTheta2);
    for (std::size_t r = 90; r < 100; ++r)
        for (std::size_t x = 10; x < 30; ++x)
            p.b.values[r * W + x] = static_cast<float>(p.a.values[r * W + x] / (0.5 * range.lower));
    const RatioInverseTable tg = RatioInverseTable::sigma_over_T(
        normal_view_geometry(kTheta1), normal_view_geometry(kTheta2), Correlation::Gaussian);
    const RatioInverseTable te = RatioInverseTable::sigma_over_T(
        normal_view_geometry(kTheta1), normal_view_geometry(kTheta2), Correlation::Exponential);
    auto relative = [](double got, double expected) {
        return std::abs(got - expected) / std::abs(expected);
    };
    for (const std::size_t threads : {std::size_t{1}, std::size_t{3}, std::size_t{0}}) {
        MapOptions o;
        o.window_px = 1;
        o.threads = std::max<std::size_t>(threads, 1);
        o.check_registration = false;
        o.both_correlations = true;
        o.ratio_layer = true;
        // threads 0: one thread, the baseline build of the row loops (no AVX).
        const MapInstructionSet before = limit_map_instruction_set(
            threads != 0 ? MapInstructionSet::Best : MapInstructionSet::Baseline);
        const RoughnessMap map = roughness_map(flat_captures(p), o);
        limit_map_instruction_set(before);
        ASSERT_EQ(map.width * map.height, W * H);
        std::size_t missing = 0, no_solution = 0, valid = 0;
        double worst = 0.0, worst_se = 0.0;
        for (std::size_t r = 0; r < H; ++r)
            for (std::size_t x = 0; x < W; ++x) {
                const std::size_t i = r * W + x;
                auto used = [&](std::size_t q) { return p.a.flags[q] == 0 && p.b.flags[q] == 0; };
                double n = 0, s1 = 0, s2 = 0;
                for (std::size_t rr = r >= 2 ? r - 2 : 0; rr <= std::min(H - 1, r + 2); ++rr)
                    for (std::size_t xx = x >= 2 ? x - 2 : 0; xx <= std::min(W - 1, x + 2); ++xx)
                        if (used(rr * W + xx)) {
                            n += 1;
                            s1 += p.a.values[rr * W + xx];
                            s2 += p.b.values[rr * W + xx];
                        }
                if (!used(i) || n < 3) {
                    ++missing;
                    EXPECT_EQ(map.roughness_class[i], kClassNone);
                    EXPECT_TRUE(std::isnan(map.E1_over_E2[i]));
                    continue;
                }
                const double m1 = s1 / n, m2 = s2 / n;
                double v1 = 0, v2 = 0, c12 = 0;
                for (std::size_t rr = r >= 2 ? r - 2 : 0; rr <= std::min(H - 1, r + 2); ++rr)
                    for (std::size_t xx = x >= 2 ? x - 2 : 0; xx <= std::min(W - 1, x + 2); ++xx)
                        if (used(rr * W + xx)) {
                            const double d1 = p.a.values[rr * W + xx] - m1;
                            const double d2 = p.b.values[rr * W + xx] - m2;
                            v1 += d1 * d1 / (n - 1);
                            v2 += d2 * d2 / (n - 1);
                            c12 += d1 * d2 / (n - 1);
                        }
                const double sd =
                    std::sqrt(v1 / (m1 * m1) + v2 / (m2 * m2) - 2.0 * c12 / (m1 * m2));
                const double ratio =
                    static_cast<double>(p.a.values[i]) / static_cast<double>(p.b.values[i]);
                EXPECT_LT(relative(map.E1_over_E2[i], ratio), 1e-6) << i;
                const auto vg = tg.lookup(std::log(ratio)), ve = te.lookup(std::log(ratio));
                if (!vg) {
                    ++no_solution;
                    EXPECT_FALSE(ve.has_value()) << i;
                    EXPECT_EQ(map.roughness_class[i], kClassNone);
                    EXPECT_TRUE(std::isnan(map.sigma_over_T_gaussian[i]));
                    EXPECT_TRUE(std::isnan(map.sigma_over_T_exponential_stderr[i]));
                    continue;
                }
                ++valid;
                ASSERT_TRUE(ve.has_value()) << i;
                worst = std::max({worst, relative(map.sigma_over_T_gaussian[i], vg->x),
                                  relative(map.sigma_over_T_exponential[i], ve->x)});
                worst_se = std::max({worst_se,
                                     relative(map.sigma_over_T_gaussian_stderr[i],
                                              std::abs(vg->dx_dlog_ratio) * sd),
                                     relative(map.sigma_over_T_exponential_stderr[i],
                                              std::abs(ve->dx_dlog_ratio) * sd)});
                EXPECT_EQ(map.roughness_class[i],
                          static_cast<std::uint8_t>(roughness_class_of_sigma_over_T(vg->x)))
                    << i;
            }
        std::printf(
            "%s: %zu valid, %zu missing, %zu no solution; largest relative "
            "difference σ/T %.2e, stderr %.2e\n",
            threads == 0 ? "baseline build" : (threads == 1 ? "1 thread" : "3 threads"), valid,
            missing, no_solution, worst, worst_se);
        EXPECT_EQ(map.valid, valid);
        EXPECT_EQ(map.missing, missing);
        EXPECT_EQ(map.no_solution, no_solution);
        EXPECT_GE(no_solution, 150U);
        EXPECT_GE(missing, 400U);
        EXPECT_LT(worst, 1e-6);
        EXPECT_LT(worst_se, 1e-5);
        // The per-class means are those of the class layer's cells.
        for (std::size_t c = 0; c < 3; ++c) {
            double sum = 0;
            std::size_t count = 0;
            for (std::size_t i = 0; i < W * H; ++i)
                if (map.roughness_class[i] == c) {
                    sum += map.sigma_over_T_gaussian[i];
                    ++count;
                }
            EXPECT_EQ(map.classes[c].count, count);
            if (count > 0) {
                ASSERT_TRUE(map.classes[c].mean_sigma_over_T.has_value());
                EXPECT_NEAR(map.classes[c].mean_sigma_over_T->value, sum / count,
                            1e-12 * sum / count);
            }
        }
    }
}

TEST(RoughnessMap, MisregisteredPairIsRefusedUnlessAllowed) {
    const std::size_t W = 384, H = 128;
    const auto labels1 = strip_labels(W, H);
    const auto labels2 = strip_labels(W, H, 5);  // the second capture moved 5 px right
    const LitPair p =
        render_lit_pair(plane(W, H), strip_truths(), labels1, labels2, kTheta1, kTheta2, 31);
    MapOptions o;
    o.window_px = 16;
    try {
        (void)roughness_map(flat_captures(p), o);
        ADD_FAILURE() << "a 5 px shift was accepted";
    } catch (const DataError& e) {
        const std::string m = e.what();
        std::printf("%s\n", m.c_str());
        EXPECT_NE(m.find("max_shift_px is 1 px"), std::string::npos) << m;
        EXPECT_NE(m.find("shifted by (5"), std::string::npos) << m;
    }
    o.allow_misregistration = true;
    const RoughnessMap map = roughness_map(flat_captures(p), o);
    ASSERT_TRUE(map.registration.has_value());
    EXPECT_NEAR(map.registration->shift_x_px, 5.0, 0.3);
    EXPECT_NEAR(map.registration->shift_y_px, 0.0, 0.3);
    EXPECT_FALSE(map.warnings.empty());
    // The same pair unshifted passes.
    const LitPair q =
        render_lit_pair(plane(W, H), strip_truths(), labels1, labels1, kTheta1, kTheta2, 31);
    o.allow_misregistration = false;
    EXPECT_NO_THROW((void)roughness_map(flat_captures(q), o));
}

// T given σ: a very rough surface (the exact series, ≈ Eq. 4 at g ≈ 4000) and a slightly rough
// one (Eq. 15 through the table of the slightly-rough diffuse term), each with its class by g.
TEST(RoughnessMap, CorrelationLengthGivenSigma) {
    const std::size_t W = 64, H = 64;
    {
        sim::SurfaceTruth t = very_rough_truth(1.0);
        t.sigma_um = 3.0;
        t.T_um = 3.0;
        const LitPair p = render_lit_pair(plane(W, H), {t}, {}, {}, kTheta1, kTheta2, 41);
        MapOptions o;
        o.sigma_um = 3.0;
        o.sigma_um_stderr = 0.03;
        const RoughnessMap map = roughness_map(flat_captures(p), o);
        ASSERT_EQ(map.T_um.size(), map.width * map.height);
        std::vector<float> T;
        for (std::size_t i = 0; i < map.T_um.size(); ++i) {
            EXPECT_EQ(map.roughness_class_g[i], kClassVeryRough);
            if (std::isfinite(map.T_um[i])) T.push_back(map.T_um[i]);
        }
        std::nth_element(T.begin(), T.begin() + T.size() / 2, T.end());
        std::printf("very rough: median T = %.4f µm (truth 3), %zu tiles\n", T[T.size() / 2],
                    T.size());
        EXPECT_NEAR(T[T.size() / 2], 3.0, 0.05);
    }
    {
        // g = (2π σ/λ)² (cos θi + 1)² ≈ 0.045 at 30°: slightly rough. A long patch (X) makes
        // the coherent term (∝ 1/X², Eq. 1) negligible beside the diffuse one (∝ 1/X).
        sim::SurfaceTruth t;
        t.model = sim::BrightnessModel::MeanScatteredPower;
        t.sigma_um = 0.01;
        t.T_um = 0.5;
        t.model_options.regime = Regime::SlightlyRough;
        t.model_options.patch_x_um = 1e7;
        const std::vector<Geometry> geoms{normal_view_geometry(kTheta1),
                                          normal_view_geometry(kTheta2)};
        const LitPair p = render_lit_pair(plane(W, H), {t}, {}, {}, kTheta1, kTheta2, 43);
        MapOptions o;
        o.sigma_um = 0.01;
        const RoughnessMap map = roughness_map(flat_captures(p), o);
        std::vector<float> T;
        for (std::size_t i = 0; i < map.T_um.size(); ++i) {
            EXPECT_EQ(map.roughness_class_g[i], kClassSlightlyRough);
            if (std::isfinite(map.T_um[i])) T.push_back(map.T_um[i]);
        }
        ASSERT_FALSE(T.empty());
        std::nth_element(T.begin(), T.begin() + T.size() / 2, T.end());
        // Against Eq. 15 on the noise-free ratio (the scalar estimator).
        const double ratio =
            sim::surface_brightness(t, geoms[0]) / sim::surface_brightness(t, geoms[1]);
        const double eq15 = correlation_length_from_ratio(ratio, 0.01, kTheta1, kTheta2, 0.555);
        std::printf(
            "slightly rough: median T = %.4f µm (truth 0.5, Eq. 15 on the exact ratio "
            "%.4f), %zu tiles\n",
            T[T.size() / 2], eq15, T.size());
        EXPECT_NEAR(eq15, 0.5, 2e-3);  // the coherent term, ~1e-3 of the diffuse one
        EXPECT_NEAR(T[T.size() / 2], 0.5, 0.01);
    }
}

// A sphere: every tile has its own geometry from the normal map (camera frame = scene frame for
// a camera on +Z).
TEST(RoughnessMap, NormalMapOfASphere) {
    sim::Scene scene;
    scene.shape = sim::SceneShape::Sphere;
    scene.width = 128;
    scene.height = 128;
    const double truth = 0.8;
    const LitPair p = render_lit_pair(scene, {very_rough_truth(truth)}, {}, {}, kTheta1, kTheta2,
                                      51, true, /*keep_geometry=*/true);
    std::vector<MapCapture> c(2);
    c[0].image = &p.a;
    c[0].light = sim::direction_from_angles(kTheta1, kPi);
    c[0].view = Eigen::Vector3d(0, 0, 1);
    c[1].image = &p.b;
    c[1].light = sim::direction_from_angles(kTheta2, kPi);
    c[1].view = Eigen::Vector3d(0, 0, 1);
    MapOptions o;
    o.window_px = 8;
    o.normal_map = p.c1.normal;
    const RoughnessMap map = roughness_map(c, o);
    std::vector<double> rel;
    std::size_t within = 0;
    for (std::size_t i = 0; i < map.sigma_over_T_gaussian.size(); ++i) {
        const float v = map.sigma_over_T_gaussian[i];
        if (!std::isfinite(v)) continue;
        rel.push_back(std::abs(v - truth) / truth);
        if (std::abs(v - truth) < 3.0 * map.sigma_over_T_gaussian_stderr[i] + 0.01 * truth)
            ++within;
    }
    ASSERT_GT(rel.size(), 80u);
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    std::printf(
        "sphere: %zu tiles with σ/T, %zu missing; median |error| %.2f %%, %zu within 3 "
        "sd\n",
        map.valid, map.missing, 100.0 * rel[rel.size() / 2], within);
    EXPECT_LT(rel[rel.size() / 2], 0.02);
    EXPECT_GT(static_cast<double>(within), 0.9 * static_cast<double>(rel.size()));
    EXPECT_GT(map.missing, 0u);  // the corners off the sphere
}

TEST(RoughnessMap, BadInputIsRefused) {
    const LitPair p =
        render_lit_pair(plane(32, 32), {very_rough_truth(1.0)}, {}, {}, kTheta1, kTheta2, 61);
    auto c = flat_captures(p);
    MapOptions o;
    EXPECT_THROW(roughness_map({c[0]}, o), InvalidArgument);
    EXPECT_THROW(roughness_map({}, o), InvalidArgument);
    {
        auto bad = c;
        bad[1].image = nullptr;
        EXPECT_THROW(roughness_map(bad, o), InvalidArgument);
    }
    {
        LinearImage small = p.b;
        small.width = 16;
        small.values.resize(16 * 32);
        small.flags.resize(16 * 32);
        auto bad = c;
        bad[1].image = &small;
        EXPECT_THROW(roughness_map(bad, o), InvalidArgument);
    }
    {
        MapOptions w = o;
        w.window_px = 0;
        EXPECT_THROW(roughness_map(c, w), InvalidArgument);
        w.window_px = 5000;
        EXPECT_THROW(roughness_map(c, w), InvalidArgument);
    }
    {
        auto bad = c;
        bad[1].geometry = bad[0].geometry;  // no information in the ratio
        EXPECT_THROW(roughness_map(bad, o), InvalidArgument);
        bad[1].exposure_scale = 0.0;
        EXPECT_THROW(roughness_map(bad, o), InvalidArgument);
    }
    {
        MapOptions n = o;
        std::vector<float> normals(10, 0.0f);
        n.normal_map = normals;
        EXPECT_THROW(roughness_map(c, n), InvalidArgument);  // wrong size and no light/view
    }
    {
        MapOptions r = o;
        std::vector<std::int32_t> labels(32 * 32, 3);
        r.region_labels = labels;
        r.region_names = {"a"};
        EXPECT_THROW(roughness_map(c, r), InvalidArgument);
    }
    {
        MapOptions s = o;
        s.sigma_um = -1.0;
        EXPECT_THROW(roughness_map(c, s), InvalidArgument);
    }
}

// The images' values are checked where the map reads them: a non-finite value anywhere in a
// capture (outside the registration's central crop, in a flagged pixel too, per pixel and per
// tile, with one thread or several) is an InvalidArgument naming the image and the sample.
TEST(RoughnessMap, NonFiniteValuesAreRefusedWhereverTheyAre) {
    const LitPair p =
        render_lit_pair(plane(300, 260), {very_rough_truth(0.7)}, {}, {}, kTheta1, kTheta2, 82);
    for (const std::size_t at : {std::size_t{0}, std::size_t{259 * 300 + 299}}) {
        for (const std::size_t window : {std::size_t{1}, std::size_t{4}}) {
            for (const std::size_t threads : {std::size_t{1}, std::size_t{2}}) {
                LinearImage broken = p.b;
                broken.values[at] = std::numeric_limits<float>::infinity();
                broken.flags[at] = kPixelSaturated;
                broken.info.source = "broken.tiff";
                auto c = flat_captures(p);
                c[1].image = &broken;
                MapOptions o;
                o.window_px = window;
                o.threads = threads;
                o.registration.max_side_px = 64;  // both samples outside its central crop
                try {
                    (void)roughness_map(c, o);
                    ADD_FAILURE() << "accepted an infinite value at " << at;
                } catch (const InvalidArgument& e) {
                    const std::string what = e.what();
                    EXPECT_NE(what.find("broken.tiff"), std::string::npos) << what;
                    EXPECT_NE(what.find(concat("at sample ", std::to_string(at))),
                              std::string::npos)
                        << what;
                }
            }
        }
    }
}

// A ratio outside what the model produces is counted, not thrown; flagged pixels are never used.
TEST(RoughnessMap, RatioOutsideTheModelIsCountedAsNoSolution) {
    LinearImage a, b;
    for (LinearImage* im : {&a, &b}) {
        im->width = 32;
        im->height = 32;
        im->channels = 1;
        im->values.assign(32 * 32, 0.5f);
        im->flags.assign(32 * 32, 0);
    }
    const RatioRange range = ratio_range_gaussian(kTheta1, kTheta2);
    // E1/E2 = lower / 2: below the Gaussian model's range (and the exponential's).
    for (float& v : b.values) v = static_cast<float>(0.5 * 2.0 / range.lower);
    // The top-left tile: every pixel flagged.
    for (std::size_t r = 0; r < 8; ++r)
        for (std::size_t x = 0; x < 8; ++x) a.flags[r * 32 + x] = kPixelSaturated;
    std::vector<MapCapture> c(2);
    c[0].image = &a;
    c[0].geometry = normal_view_geometry(kTheta1);
    c[1].image = &b;
    c[1].geometry = normal_view_geometry(kTheta2);
    MapOptions o;
    o.window_px = 8;
    const RoughnessMap map = roughness_map(c, o);
    EXPECT_EQ(map.valid, 0u);
    EXPECT_EQ(map.missing, 1u);
    EXPECT_EQ(map.no_solution, 15u);
    EXPECT_TRUE(std::isnan(map.sigma_over_T_gaussian[0]));
    EXPECT_EQ(map.roughness_class[5], kClassNone);
    for (const auto& s : map.classes) {
        EXPECT_EQ(s.count, 0u);
        EXPECT_EQ(s.fraction, 0.0);
        EXPECT_FALSE(s.mean_sigma_over_T.has_value());
    }
    EXPECT_FALSE(map.warnings.empty());
    // Per pixel as well.
    o.window_px = 1;
    const RoughnessMap pixels = roughness_map(c, o);
    EXPECT_EQ(pixels.missing, 64u);
    EXPECT_EQ(pixels.no_solution, 32u * 32u - 64u);
}

TEST(RoughnessMap, MoreThanTwoCapturesUseTheFirstTwoWithAWarning) {
    const LitPair p =
        render_lit_pair(plane(32, 32), {very_rough_truth(1.0)}, {}, {}, kTheta1, kTheta2, 71);
    auto c = flat_captures(p);
    c.push_back(c[1]);
    const RoughnessMap three = roughness_map(c, MapOptions{});
    c.pop_back();
    const RoughnessMap two = roughness_map(c, MapOptions{});
    EXPECT_EQ(three.sigma_over_T_gaussian, two.sigma_over_T_gaussian);
    EXPECT_EQ(three.warnings.size(), two.warnings.size() + 1);
}

TEST(RoughnessClassOfSigmaOverT, Thresholds) {
    EXPECT_EQ(roughness_class_of_sigma_over_T(0.3), RoughnessClass::SlightlyRough);
    EXPECT_EQ(roughness_class_of_sigma_over_T(0.33), RoughnessClass::ModeratelyRough);
    EXPECT_EQ(roughness_class_of_sigma_over_T(3.1), RoughnessClass::ModeratelyRough);
    EXPECT_EQ(roughness_class_of_sigma_over_T(3.2), RoughnessClass::VeryRough);
    // One decade of (σ/T)² either side of 1.
    EXPECT_NEAR(kSlightlyRoughMaxSigmaOverT * kSlightlyRoughMaxSigmaOverT, 0.1, 1e-15);
    EXPECT_NEAR(kVeryRoughMinSigmaOverT * kVeryRoughMinSigmaOverT, 10.0, 1e-14);
}

}  // namespace
}  // namespace roughscope::image

namespace roughscope::image {
namespace {

// A noisy pair (σ/T = 0.6) with every flag_step-th pixel of capture 1 saturated and every
// ratio_step-th pixel (from ratio_first) at a ratio below the model's range.
LitPair pair_with_flags_and_no_solutions(std::size_t W, std::size_t H, std::uint64_t seed,
                                         std::size_t flag_step, std::size_t ratio_first,
                                         std::size_t ratio_step) {
    LitPair p =
        render_lit_pair(plane(W, H), {very_rough_truth(0.6)}, {}, {}, kTheta1, kTheta2, seed);
    const RatioRange range = ratio_range_gaussian(kTheta1, kTheta2);
    for (std::size_t i = 0; i < W * H; i += flag_step) p.a.flags[i] = kPixelSaturated;
    for (std::size_t i = ratio_first; i < W * H; i += ratio_step)
        p.b.values[i] = static_cast<float>(p.a.values[i] / (0.5 * range.lower));
    return p;
}

// The per-pixel map's builds of its row loops (the processor's best of the compiler's clones,
// core/target_clones.hpp, against the baseline build) give the same map, bit for bit (a noisy
// pair with flagged pixels and ratios outside the model's range).
TEST(RoughnessMap, VectorBuildsGiveTheSameMap) {
    const LitPair p = pair_with_flags_and_no_solutions(301, 77, 9, 37, 5, 53);
    MapOptions o;
    o.window_px = 1;
    o.check_registration = false;
    o.both_correlations = true;
    o.ratio_layer = true;
    const MapInstructionSet before = limit_map_instruction_set(MapInstructionSet::Baseline);
    ASSERT_EQ(map_instruction_set(), MapInstructionSet::Baseline);
    const RoughnessMap baseline = roughness_map(flat_captures(p), o);
    auto same = [](const MapLayerValues& a, const MapLayerValues& b) {
        if (a.size() != b.size()) return false;
        for (std::size_t i = 0; i < a.size(); ++i)
            if (!((std::isnan(a[i]) && std::isnan(b[i])) || a[i] == b[i])) return false;
        return true;
    };
    {
        limit_map_instruction_set(MapInstructionSet::Best);
        ASSERT_EQ(map_instruction_set(), MapInstructionSet::Best);
        const RoughnessMap fast = roughness_map(flat_captures(p), o);
        EXPECT_TRUE(same(fast.E1_over_E2, baseline.E1_over_E2));
        EXPECT_TRUE(same(fast.sigma_over_T_gaussian, baseline.sigma_over_T_gaussian));
        EXPECT_TRUE(same(fast.sigma_over_T_gaussian_stderr, baseline.sigma_over_T_gaussian_stderr));
        EXPECT_TRUE(same(fast.sigma_over_T_exponential, baseline.sigma_over_T_exponential));
        EXPECT_TRUE(
            same(fast.sigma_over_T_exponential_stderr, baseline.sigma_over_T_exponential_stderr));
        EXPECT_TRUE(fast.roughness_class == baseline.roughness_class);
        EXPECT_EQ(fast.valid, baseline.valid);
        EXPECT_EQ(fast.missing, baseline.missing);
        EXPECT_EQ(fast.no_solution, baseline.no_solution);
        EXPECT_GT(fast.no_solution, 100U);
        EXPECT_GT(fast.missing, 300U);
        for (std::size_t c = 0; c < 3; ++c) {
            EXPECT_EQ(fast.classes[c].count, baseline.classes[c].count);
            ASSERT_EQ(fast.classes[c].mean_sigma_over_T.has_value(),
                      baseline.classes[c].mean_sigma_over_T.has_value());
            if (fast.classes[c].mean_sigma_over_T) {
                EXPECT_EQ(fast.classes[c].mean_sigma_over_T->value,
                          baseline.classes[c].mean_sigma_over_T->value);
            }
        }
    }
    limit_map_instruction_set(before);
}

// Bands of rows on several threads give the same map as one thread, per pixel and per tile.
TEST(RoughnessMap, ThreadsDoNotChangeTheResult) {
    const LitPair p =
        render_lit_pair(plane(300, 260), {very_rough_truth(0.7)}, {}, {}, kTheta1, kTheta2, 81);
    for (const std::size_t window : {std::size_t{1}, std::size_t{2}}) {
        MapOptions o;
        o.window_px = window;
        o.threads = 1;
        o.both_correlations = true;
        const RoughnessMap one = roughness_map(flat_captures(p), o);
        o.threads = 3;
        const RoughnessMap three = roughness_map(flat_captures(p), o);
        ASSERT_EQ(one.sigma_over_T_gaussian.size(), three.sigma_over_T_gaussian.size());
        for (std::size_t i = 0; i < one.sigma_over_T_gaussian.size(); ++i) {
            const float a = one.sigma_over_T_gaussian[i], b = three.sigma_over_T_gaussian[i];
            ASSERT_TRUE((std::isnan(a) && std::isnan(b)) || a == b) << window << " " << i;
            ASSERT_EQ(one.sigma_over_T_exponential_stderr[i],
                      three.sigma_over_T_exponential_stderr[i]);
        }
        EXPECT_EQ(one.valid, three.valid);
        EXPECT_EQ(one.missing, three.missing);
        EXPECT_EQ(one.no_solution, three.no_solution);
    }
}

// The layers not asked for are not made (empty, and no count of the other correlation's
// failures); the layers made are the same, bit for bit, as when every layer is asked for — per
// pixel (each of the row loop's builds) and per tile, either correlation first, with regions
// (their statistics pool ln E1/E2 and give both correlations either way).
TEST(RoughnessMap, LayersNotAskedForAreNotMadeAndTheRestIsTheSame) {
    const std::size_t W = 203, H = 71;
    const LitPair p = pair_with_flags_and_no_solutions(W, H, 5, 41, 7, 59);
    std::vector<std::int32_t> labels(W * H);
    for (std::size_t i = 0; i < W * H; ++i) labels[i] = (i % W) < W / 2 ? 0 : -1;
    auto same = [](const MapLayerValues& a, const MapLayerValues& b) {
        if (a.size() != b.size()) return false;
        for (std::size_t i = 0; i < a.size(); ++i)
            if (!((std::isnan(a[i]) && std::isnan(b[i])) || a[i] == b[i])) return false;
        return true;
    };
    auto same_estimate = [](const std::optional<Estimate>& a, const std::optional<Estimate>& b) {
        return a.has_value() == b.has_value() &&
               (!a ||
                (a->value == b->value && (a->std_error == b->std_error ||
                                          (std::isnan(a->std_error) && std::isnan(b->std_error)))));
    };
    const MapInstructionSet before = map_instruction_set();
    for (const MapInstructionSet isa : kInstructionSets)
        for (const std::size_t window : {std::size_t{1}, std::size_t{4}})
            for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential})
                for (const bool regions : {false, true}) {
                    limit_map_instruction_set(isa);
                    MapOptions o;
                    o.window_px = window;
                    o.correlation = c;
                    o.check_registration = false;
                    if (regions) {
                        o.region_labels = labels;
                        o.region_names = {"left"};
                    }
                    o.both_correlations = true;
                    o.ratio_layer = true;
                    const RoughnessMap full = roughness_map(flat_captures(p), o);
                    ASSERT_TRUE(full.no_solution_other.has_value());
                    EXPECT_GT(*full.no_solution_other, 0U);
                    for (const bool both : {false, true})
                        for (const bool ratio : {false, true}) {
                            SCOPED_TRACE(::testing::Message()
                                         << "isa " << static_cast<int>(isa) << " window " << window
                                         << " exponential " << (c == Correlation::Exponential)
                                         << " regions " << regions << " both " << both << " ratio "
                                         << ratio);
                            o.both_correlations = both;
                            o.ratio_layer = ratio;
                            const RoughnessMap m = roughness_map(flat_captures(p), o);
                            const Correlation oc = other_correlation(c);
                            EXPECT_EQ(m.sigma_over_T(c).size(), m.width * m.height);
                            EXPECT_TRUE(same(m.sigma_over_T(c), full.sigma_over_T(c)));
                            EXPECT_TRUE(
                                same(m.sigma_over_T_stderr(c), full.sigma_over_T_stderr(c)));
                            const auto& other = m.sigma_over_T(oc);
                            const auto& other_full = full.sigma_over_T(oc);
                            const auto& other_se = m.sigma_over_T_stderr(oc);
                            const auto& other_se_full = full.sigma_over_T_stderr(oc);
                            if (both) {
                                EXPECT_TRUE(same(other, other_full));
                                EXPECT_TRUE(same(other_se, other_se_full));
                                EXPECT_EQ(m.no_solution_other, full.no_solution_other);
                            } else {
                                EXPECT_TRUE(other.empty());
                                EXPECT_TRUE(other_se.empty());
                                EXPECT_FALSE(m.no_solution_other.has_value());
                            }
                            if (ratio)
                                EXPECT_TRUE(same(m.E1_over_E2, full.E1_over_E2));
                            else
                                EXPECT_TRUE(m.E1_over_E2.empty());
                            EXPECT_TRUE(m.roughness_class == full.roughness_class);
                            EXPECT_EQ(m.valid, full.valid);
                            EXPECT_EQ(m.missing, full.missing);
                            EXPECT_EQ(m.no_solution, full.no_solution);
                            for (std::size_t k = 0; k < 3; ++k) {
                                EXPECT_EQ(m.classes[k].count, full.classes[k].count);
                                EXPECT_TRUE(same_estimate(m.classes[k].mean_sigma_over_T,
                                                          full.classes[k].mean_sigma_over_T));
                            }
                            ASSERT_EQ(m.regions.size(), regions ? 1U : 0U);
                            for (std::size_t k = 0; k < m.regions.size(); ++k) {
                                const RegionMapStatistics &a = m.regions[k], &b = full.regions[k];
                                EXPECT_EQ(a.count, b.count);
                                EXPECT_TRUE(same_estimate(a.mean_sigma_over_T_gaussian,
                                                          b.mean_sigma_over_T_gaussian));
                                EXPECT_TRUE(same_estimate(a.mean_sigma_over_T_exponential,
                                                          b.mean_sigma_over_T_exponential));
                                EXPECT_TRUE(a.mean_sigma_over_T_gaussian.has_value());
                                EXPECT_TRUE(a.mean_sigma_over_T_exponential.has_value());
                            }
                        }
                }
    limit_map_instruction_set(before);
}

// A colour capture is read as its channel average and a capture's exposure scale s_k divides its
// values: three equal channels give the one-channel map, and a capture stored 4× brighter with
// s_k = 4 gives the same map — bit for bit (both are exact in binary), per pixel and per tile.
// A non-finite value in any channel is refused, naming the capture.
TEST(RoughnessMap, ColourChannelsAndExposureScalesAreTheStoredValuesBrightness) {
    const std::size_t W = 97, H = 83;
    LitPair p = render_lit_pair(plane(W, H), {very_rough_truth(0.8)}, {}, {}, kTheta1, kTheta2, 13);
    for (std::size_t i = 0; i < W * H; i += 29) p.b.flags[i] = kPixelClippedLow;
    auto colour = [](const LinearImage& mono) {
        LinearImage c = mono;
        c.channels = 3;
        c.values.resize(3 * mono.values.size());
        for (std::size_t ch = 0; ch < 3; ++ch)
            std::copy(mono.values.begin(), mono.values.end(),
                      c.values.begin() + static_cast<std::ptrdiff_t>(ch * mono.values.size()));
        return c;
    };
    LinearImage brighter = p.b;
    for (float& v : brighter.values) v *= 4.0f;
    const LinearImage colour_a = colour(p.a), colour_b = colour(p.b);
    auto same = [](const MapLayerValues& a, const MapLayerValues& b) {
        if (a.size() != b.size() || a.empty()) return false;
        for (std::size_t i = 0; i < a.size(); ++i)
            if (!((std::isnan(a[i]) && std::isnan(b[i])) || a[i] == b[i])) return false;
        return true;
    };
    for (const std::size_t window : {std::size_t{1}, std::size_t{5}}) {
        SCOPED_TRACE(window);
        MapOptions o;
        o.window_px = window;
        o.check_registration = false;
        o.both_correlations = true;
        o.ratio_layer = true;
        const RoughnessMap mono = roughness_map(flat_captures(p), o);
        EXPECT_GT(mono.valid, mono.width * mono.height / 2);
        auto c = flat_captures(p);
        c[0].image = &colour_a;
        c[1].image = &colour_b;
        const RoughnessMap col = roughness_map(c, o);
        c = flat_captures(p);
        c[1].image = &brighter;
        c[1].exposure_scale = 4.0;
        const RoughnessMap scaled = roughness_map(c, o);
        for (const RoughnessMap* m : {&col, &scaled}) {
            EXPECT_TRUE(same(m->E1_over_E2, mono.E1_over_E2));
            EXPECT_TRUE(same(m->sigma_over_T_gaussian, mono.sigma_over_T_gaussian));
            EXPECT_TRUE(same(m->sigma_over_T_gaussian_stderr, mono.sigma_over_T_gaussian_stderr));
            EXPECT_TRUE(same(m->sigma_over_T_exponential, mono.sigma_over_T_exponential));
            EXPECT_TRUE(m->roughness_class == mono.roughness_class);
            EXPECT_EQ(m->valid, mono.valid);
            EXPECT_EQ(m->missing, mono.missing);
        }
        // Without the exposure scale the brighter capture is a different ratio (4× smaller).
        c[1].exposure_scale = 1.0;
        const RoughnessMap unscaled = roughness_map(c, o);
        EXPECT_FALSE(same(unscaled.E1_over_E2, mono.E1_over_E2));
        // A NaN in the third channel of one pixel of the colour pair.
        LinearImage broken = colour_b;
        broken.values[2 * W * H + 40 * W + 50] = std::numeric_limits<float>::quiet_NaN();
        c = flat_captures(p);
        c[0].image = &colour_a;
        c[1].image = &broken;
        try {
            (void)roughness_map(c, o);
            ADD_FAILURE() << "a NaN in a channel was accepted";
        } catch (const InvalidArgument& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(concat("at sample ", std::to_string(2 * W * H + 40 * W + 50))),
                      std::string::npos)
                << what;
        }
    }
}

}  // namespace
}  // namespace roughscope::image
