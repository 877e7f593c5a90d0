// Levelling (statistics.hpp): exact backgrounds are removed, σ and the ACF are invariant under an
// added tilt (plane levelling) or cubic (order-3 levelling), and every "too few points" path.
#include <cmath>
#include <cstddef>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/statistics.hpp"
#include "test_statistics_data.hpp"

namespace roughscope::surface {
namespace {

using testdata::kNaN;

double max_abs(const HeightMap& m) {
    double r = 0;
    for (double z : m.heights_um)
        if (!std::isnan(z)) r = std::max(r, std::abs(z));
    return r;
}

HeightMap plus(const HeightMap& m, double (*background)(double, double)) {
    HeightMap out = m;
    for (std::size_t iy = 0; iy < m.ny; ++iy)
        for (std::size_t ix = 0; ix < m.nx; ++ix)
            out.at(ix, iy) +=
                background(static_cast<double>(ix) * m.dx_um, static_cast<double>(iy) * m.dy_um);
    return out;
}

double tilt(double x, double y) { return 3.0 + 0.7 * x - 0.4 * y; }
double cubic(double x, double y) {
    return 1.0 - 0.2 * x + 0.05 * y + 0.01 * x * y - 0.003 * x * x + 2e-4 * x * x * x -
           1e-4 * x * y * y + 5e-5 * y * y * y;
}
double row_lines(double x, double y) { return 2.0 * y + (0.1 + 0.01 * y) * x; }

TEST(SurfaceLevel, RemovesExactBackgrounds) {
    HeightMap zero = make_height_map(20, 15, 0.5, 0.75);
    zero.at(3, 4) = kNaN;
    EXPECT_LT(max_abs(level(plus(zero, tilt), Leveling::plane)), 1e-12);
    EXPECT_LT(max_abs(level(plus(zero, cubic), Leveling::polynomial, 3)), 1e-12);
    EXPECT_GT(max_abs(level(plus(zero, cubic), Leveling::polynomial, 2)), 1e-4);
    EXPECT_LT(max_abs(level(plus(zero, row_lines), Leveling::line)), 1e-12);
    EXPECT_GT(max_abs(level(plus(zero, row_lines), Leveling::plane)), 1e-2);
    const HeightMap shifted = level(plus(zero, tilt), Leveling::mean);
    EXPECT_GT(max_abs(shifted), 1.0);  // the tilt stays
    double sum = 0;
    for (double z : shifted.heights_um)
        if (!std::isnan(z)) sum += z;
    EXPECT_NEAR(sum, 0.0, 1e-9);
    EXPECT_TRUE(std::isnan(level(zero, Leveling::plane).at(3, 4)));
    EXPECT_TRUE(bitwise_equal(level(plus(zero, tilt), Leveling::none), plus(zero, tilt)));
}

TEST(SurfaceLevel, ProfilePolynomialIgnoresY) {
    HeightMap p = make_height_map(50, 1, 0.2, 0.2);
    for (std::size_t k = 0; k < 50; ++k) {
        const double x = 0.2 * static_cast<double>(k);
        p.heights_um[k] = 1 + x - 0.3 * x * x + 0.02 * x * x * x;
    }
    EXPECT_LT(max_abs(level(p, Leveling::polynomial, 3)), 1e-11);
    EXPECT_GT(max_abs(level(p, Leveling::plane)), 1e-2);
}

void expect_same_statistics(const SurfaceStatistics& a, const SurfaceStatistics& b) {
    EXPECT_NEAR(a.sigma_um, b.sigma_um, 1e-10);
    ASSERT_EQ(a.acf_x.y.size(), b.acf_x.y.size());
    for (std::size_t j = 0; j < a.acf_x.y.size(); ++j)
        EXPECT_NEAR(a.acf_x.y[j], b.acf_x.y[j], 1e-9);
    ASSERT_EQ(a.acf_y.y.size(), b.acf_y.y.size());
    for (std::size_t j = 0; j < a.acf_y.y.size(); ++j)
        EXPECT_NEAR(a.acf_y.y[j], b.acf_y.y[j], 1e-9);
    ASSERT_EQ(a.T_um.has_value(), b.T_um.has_value());
    if (a.T_um) {
        EXPECT_NEAR(*a.T_um, *b.T_um, 1e-9);
    }
}

TEST(SurfaceLevel, SigmaAndAcfInvariantUnderTiltAfterPlaneLevelling) {
    const HeightMap m = testdata::ar1_map(96, 40, 4.0, 71);
    HeightMap holes = m;
    holes.at(10, 10) = kNaN;
    holes.at(50, 33) = kNaN;
    for (const HeightMap& base : {m, holes}) {
        StatisticsOptions o;  // plane levelling
        const SurfaceStatistics a = surface_statistics(base, o);
        const SurfaceStatistics b = surface_statistics(plus(base, tilt), o);
        expect_same_statistics(a, b);
        // The check can fail: without levelling the tilt changes σ.
        StatisticsOptions mean;
        mean.leveling = Leveling::mean;
        EXPECT_GT(surface_statistics(plus(base, tilt), mean).sigma_um, 2 * a.sigma_um);
    }
}

TEST(SurfaceLevel, SigmaAndAcfInvariantUnderCubicAfterOrderThreeLevelling) {
    const HeightMap m = testdata::ar1_map(80, 60, 3.0, 72);
    StatisticsOptions o;
    o.leveling = Leveling::polynomial;
    o.polynomial_order = 3;
    expect_same_statistics(surface_statistics(m, o), surface_statistics(plus(m, cubic), o));
    StatisticsOptions plane;
    EXPECT_GT(std::abs(surface_statistics(plus(m, cubic), plane).sigma_um -
                       surface_statistics(m, plane).sigma_um),
              1e-3);
}

TEST(SurfaceLevel, RejectsBadOrderAndTooFewPoints) {
    const HeightMap m = testdata::noise_map(10, 10, 73);
    EXPECT_NO_THROW(level(m, Leveling::polynomial, 1));
    EXPECT_THROW(level(m, Leveling::polynomial, 0), InvalidArgument);
    EXPECT_THROW(level(m, Leveling::polynomial, 4), InvalidArgument);
    EXPECT_NO_THROW(level(m, Leveling::plane, 99));  // the order is used by polynomial only

    HeightMap two = make_height_map(10, 10, 1, 1);
    two.heights_um.assign(100, kNaN);
    two.at(1, 1) = 1;
    two.at(5, 7) = 2;
    EXPECT_NO_THROW(level(two, Leveling::mean));
    EXPECT_THROW(level(two, Leveling::plane), InvalidArgument);  // 3 points needed

    HeightMap one_row = make_height_map(10, 10, 1, 1);
    one_row.heights_um.assign(100, kNaN);
    for (std::size_t ix = 0; ix < 10; ++ix) one_row.at(ix, 4) = static_cast<double>(ix);
    EXPECT_NO_THROW(level(one_row, Leveling::line));
    EXPECT_THROW(level(one_row, Leveling::plane), InvalidArgument);  // collinear points

    HeightMap nine = testdata::noise_map(3, 3, 74);  // 9 points < 10 terms of a cubic
    EXPECT_NO_THROW(level(nine, Leveling::polynomial, 2));
    EXPECT_THROW(level(nine, Leveling::polynomial, 3), InvalidArgument);

    HeightMap column = testdata::noise_map(1, 8, 75);  // every row has one point
    EXPECT_NO_THROW(level(column, Leveling::mean));
    EXPECT_THROW(level(column, Leveling::line), InvalidArgument);

    HeightMap bad = m;
    bad.dx_um = 0;
    EXPECT_THROW(level(bad, Leveling::none), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::surface
