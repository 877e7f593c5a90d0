// The fast e^{iθ} of the Kirchhoff sums (src/simulation/phasor.hpp) against std::cos/std::sin.
#include <cmath>
#include <complex>
#include <limits>

#include <gtest/gtest.h>

#include "simulation/phasor.hpp"

namespace roughscope::simulation::detail {
namespace {

TEST(Phasor, AgreesWithTheLibmToAFewUlpsOfOne) {
    const PhasorTable& table = phasor_table();
    double worst = 0.0;
    // A dense sweep of |θ| < 2e5 (exact reduction) with irrational steps, and the table nodes.
    for (double theta = -2e5; theta < 2e5; theta += 0.7071067811865476 * 3.3) {
        const std::complex<double> e = unit_phasor(theta, table);
        worst = std::max(worst, std::abs(e - std::polar(1.0, theta)));
    }
    for (int k = -5000; k <= 5000; ++k) {
        const double theta = k * (2.0 * 3.14159265358979323846 / 4096.0);
        worst = std::max(worst, std::abs(unit_phasor(theta, table) - std::polar(1.0, theta)));
    }
    EXPECT_LT(worst, 1e-15);  // ~4.5 ulps of 1
    // Beyond the exact range the error follows θ's own rounding (ulp(θ)), not more.
    for (const double theta : {3.3e5, 7.123456789e7, 1.0e9 + 0.5, -9.87654321e11}) {
        const double ulp = std::nextafter(std::abs(theta), INFINITY) - std::abs(theta);
        EXPECT_LT(std::abs(unit_phasor(theta, table) - std::polar(1.0, theta)), 4.0 * ulp + 1e-15)
            << theta;
    }
    EXPECT_NEAR(std::abs(unit_phasor(0.0, table) - std::complex<double>(1.0, 0.0)), 0.0, 1e-300);
}

}  // namespace
}  // namespace roughscope::simulation::detail
