// The Poisson-weighted B–K series sums (Eq. 2 and the exact exponential series), checked against
//  * 40-digit mpmath reference values stored in tests/data/series_reference.csv
//    (generated once by scripts/gen_reference.py; this test never runs mpmath),
//  * closed forms at T²v_xy² = 0: Σ gⁿ/(n! n) = Ei(g) − γ − ln g (std::expint), and its
//    asymptotic expansion e^{−g}Ei(g) ~ (1/g) Σ k!/g^k for g up to 1e7,
//  * the identity d/dg[e^g S_E(g, 0)] = e^g S_G(g, 0)/g that links the two sums,
//  * an independent long-double term-by-term summation on a dense grid (continuity across the
//    narrow-peak / trapezoid switch of the implementation),
//  * the textbook (naive) summation, which agrees for small g and breaks beyond g ≈ 709.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"

namespace {

using roughscope::Correlation;
using roughscope::diffuse_series_sum_naive;
using roughscope::exponential_series_sum;
using roughscope::gaussian_series_sum;

struct ReferenceRow {
    std::string kind;  // "gaussian" or "exponential"
    std::string g_text, X_text;
    double g = 0.0, X = 0.0;  // X = T² v_xy²
    long double value = 0.0L;
    int line = 0;
};

std::string reference_path() {
    return std::string(ROUGHSCOPE_TEST_DATA_DIR) + "/series_reference.csv";
}

// The CSV is part of the repository (not optional data): a missing or malformed file fails.
std::vector<ReferenceRow> load_reference() {
    std::ifstream in(reference_path());
    if (!in) throw std::runtime_error("cannot open " + reference_path());
    std::string line;
    std::getline(in, line);
    if (line != "kind,g,T2_vxy2,value")
        throw std::runtime_error(reference_path() + ": unexpected header '" + line + "'");
    std::vector<ReferenceRow> rows;
    int line_no = 1;
    while (std::getline(in, line)) {
        ++line_no;
        if (line.empty()) continue;
        std::stringstream ss(line);
        ReferenceRow r;
        std::string value_text;
        if (!std::getline(ss, r.kind, ',') || !std::getline(ss, r.g_text, ',') ||
            !std::getline(ss, r.X_text, ',') || !std::getline(ss, value_text))
            throw std::runtime_error(reference_path() + ":" + std::to_string(line_no) +
                                     ": expected 4 fields");
        r.g = std::stod(r.g_text);
        r.X = std::stod(r.X_text);
        r.value = std::stold(value_text);
        r.line = line_no;
        rows.push_back(r);
    }
    return rows;
}

const std::vector<ReferenceRow>& reference_rows() {
    static const std::vector<ReferenceRow> rows = load_reference();
    return rows;
}

double relative_error(double computed, long double reference) {
    return static_cast<double>(
        std::fabs((static_cast<long double>(computed) - reference) / reference));
}

// Checks every row of one kind against `sum`; reports the worst row.
template <class Sum>
void check_reference_kind(const std::string& kind, Sum sum, double tolerance) {
    int count = 0;
    double worst = 0.0;
    std::string worst_row = "(none)";
    for (const ReferenceRow& r : reference_rows()) {
        if (r.kind != kind) continue;
        ++count;
        const double s = sum(r.g, r.X);
        const double err =
            std::isfinite(s) ? relative_error(s, r.value) : std::numeric_limits<double>::infinity();
        if (!(err <= worst)) {  // also catches NaN
            worst = err;
            std::ostringstream os;
            os.precision(17);
            os << "line " << r.line << ": g = " << r.g_text << ", T2_vxy2 = " << r.X_text
               << ", computed " << s << ", reference " << static_cast<double>(r.value)
               << ", relative error " << err;
            worst_row = os.str();
        }
    }
    // 27 g values × 9 X values minus the few that underflow: the file must really be there.
    EXPECT_GE(count, 230) << "too few " << kind << " rows in " << reference_path();
    EXPECT_LE(worst, tolerance) << kind << ": worst row " << worst_row;
    std::ostringstream worst_text;
    worst_text << std::scientific << std::setprecision(2) << worst;
    ::testing::Test::RecordProperty(kind + "_worst_relative_error", worst_text.str());
}

TEST(SeriesReference, FileCoversTheRequestedGrid) {
    // The extremes g = 1e−6 and 1e6 and the overflow-sensitive g = 700, 710, 750 are present for
    // both kinds, at T²v_xy² = 0 and 1e5 where the value does not underflow.
    auto has = [](const std::string& kind, const std::string& g, const std::string& X) {
        for (const ReferenceRow& r : reference_rows())
            if (r.kind == kind && r.g_text == g && r.X_text == X) return true;
        return false;
    };
    for (const char* kind : {"gaussian", "exponential"}) {
        for (const char* g : {"1e-6", "1", "700", "710", "750", "1e6"})
            EXPECT_TRUE(has(kind, g, "0")) << kind << " g=" << g;
        EXPECT_TRUE(has(kind, "1e6", "1e5")) << kind;
    }
    for (const ReferenceRow& r : reference_rows()) {
        EXPECT_GT(r.value, 1e-300L) << "line " << r.line;
        EXPECT_TRUE(r.kind == "gaussian" || r.kind == "exponential") << "line " << r.line;
    }
}

TEST(SeriesReference, GaussianSumMatchesMpmathTo1e12) {
    check_reference_kind("gaussian", gaussian_series_sum, 1e-12);
}

TEST(SeriesReference, ExponentialSumMatchesMpmathTo1e12) {
    check_reference_kind("exponential", exponential_series_sum, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// The naive summation: right for small g, broken beyond g ≈ 709 (why the careful sum exists).

TEST(SeriesNaive, AgreesWithReferenceForModerateG) {
    int count = 0;
    for (const ReferenceRow& r : reference_rows()) {
        if (r.g > 50.0) continue;
        const int terms = static_cast<int>(r.g + 10.0 * std::sqrt(r.g) + 20.0);
        const double s = r.kind == "gaussian"
                             ? diffuse_series_sum_naive(Correlation::Gaussian, r.g, r.X, terms)
                             : diffuse_series_sum_naive(Correlation::Exponential, r.g, r.X, terms);
        // The naive sum starts at n = 1 and stops after `terms`; when large X moves the peak
        // of the summand beyond that, it is not expected to agree.
        if (r.X > 4.0 * terms) continue;
        ++count;
        EXPECT_LE(relative_error(s, r.value), 1e-11)
            << r.kind << " g=" << r.g_text << " X=" << r.X_text << " naive " << s;
    }
    EXPECT_GE(count, 150);
}

TEST(SeriesNaive, BreaksBeyondG709WhereTheCarefulSumDoesNot) {
    int broken = 0;
    for (const ReferenceRow& r : reference_rows()) {
        if (r.g < 750.0 || r.g > 1e5) continue;
        const int terms = static_cast<int>(r.g + 10.0 * std::sqrt(r.g) + 20.0);
        const double naive =
            r.kind == "gaussian"
                ? diffuse_series_sum_naive(Correlation::Gaussian, r.g, r.X, terms)
                : diffuse_series_sum_naive(Correlation::Exponential, r.g, r.X, terms);
        const double careful =
            r.kind == "gaussian" ? gaussian_series_sum(r.g, r.X) : exponential_series_sum(r.g, r.X);
        EXPECT_LE(relative_error(careful, r.value), 1e-12);
        // e^{−g} underflows to 0 and Σ gⁿ/n! overflows to inf: the naive result is nan, inf or 0.
        const bool naive_broken =
            !std::isfinite(naive) || naive == 0.0 || relative_error(naive, r.value) > 1e-3;
        EXPECT_TRUE(naive_broken) << r.kind << " g=" << r.g_text << " naive " << naive;
        broken += naive_broken;
    }
    EXPECT_GE(broken, 40);
}

// ---------------------------------------------------------------------------------------------
// Closed forms and identities (independent of the stored reference and of each other).

constexpr double kEulerGamma = std::numbers::egamma;

// S_G(g, 0) = e^{−g} Σ gⁿ/(n! n) = e^{−g} [Ei(g) − γ − ln g], since d/dg Σ gⁿ/(n! n) = (e^g−1)/g.
// (Not e^{−g} Ein(g): Ein(g) = ∫₀^g (1 − e^{−t})/t dt = Σ (−1)^{n+1} gⁿ/(n! n) alternates.)
TEST(SeriesIdentity, GaussianAtZeroXEqualsExponentialIntegral) {
    // g ≥ 0.5 keeps the cancellation in Ei(g) − γ − ln g below a factor ~10.
    for (double g : {0.5, 0.77, 1.0, 2.5, 4.2, 9.9, 33.3, 64.0, 123.4, 256.0, 411.0, 700.0}) {
        const double expected = std::exp(-g) * (std::expint(g) - kEulerGamma - std::log(g));
        EXPECT_NEAR(gaussian_series_sum(g, 0.0) / expected, 1.0, 1e-13) << "g = " << g;
    }
}

TEST(SeriesIdentity, GaussianAtZeroXMatchesAsymptoticExpansionUpTo1e7) {
    // e^{−g} Ei(g) = (1/g) Σ_{k=0}^{K} k!/g^k + O(K!/g^{K+1}); for g ≥ 1000 twelve terms leave
    // < 1e−25. Then S_G(g, 0) = e^{−g}Ei(g) − e^{−g}(γ + ln g), the last term negligible.
    // (Measured: 2e−14 at g = 1e5, 3e−14 at 1e6, 1.2e−13 at 1e7; the tolerance is the 1e−12
    // contract of the reference test.)
    for (double g : {1000.0, 2345.6, 1e4, 33333.3, 1e5, 7.7e5, 1e6, 1e7}) {
        long double term = 1.0L / g, sum = 0.0L;
        for (int k = 0; k <= 12; ++k) {
            sum += term;
            term *= (k + 1.0L) / g;
        }
        EXPECT_LE(relative_error(gaussian_series_sum(g, 0.0), sum), 1e-12) << "g = " << g;
    }
}

// With A(g) = Σ gⁿ/(n! n²) and B(g) = Σ gⁿ/(n! n): A′ = B/g. In terms of the sums at X = 0,
// S_E′(g) + S_E(g) = S_G(g)/g. Checked with a central difference over g = 0.01 .. 1e6.
TEST(SeriesIdentity, ExponentialDerivativeLinksToGaussianAtZeroX) {
    for (double g = 0.01; g <= 1.01e6; g *= 1.37) {
        const double h = 1e-4 * g;
        const double dSE =
            (exponential_series_sum(g + h, 0.0) - exponential_series_sum(g - h, 0.0)) / (2.0 * h);
        const double lhs = dSE + exponential_series_sum(g, 0.0);
        const double rhs = gaussian_series_sum(g, 0.0) / g;
        EXPECT_NEAR(lhs / rhs, 1.0, 1e-7) << "g = " << g;
    }
}

// Independent term-by-term summation in long double (exponent range to 1e4932, so no overflow
// for g ≤ 1e4), with the summand's own recurrence and every term from n = 1.
long double long_double_sum(bool gaussian, double g, double X) {
    const int n_max = static_cast<int>(g + 40.0 * std::sqrt(g) + 200.0 + std::sqrt(X));
    long double w = std::exp(-static_cast<long double>(g)), sum = 0.0L;  // e^{−g} gⁿ/n!
    for (int n = 1; n <= n_max; ++n) {
        w *= static_cast<long double>(g) / n;
        const long double ln = n;
        sum += gaussian ? w / ln * std::exp(-static_cast<long double>(X) / (4.0L * ln))
                        : w * ln / std::pow(ln * ln + X, 1.5L);
    }
    return sum;
}

TEST(SeriesContinuity, DenseGridAgreesWithLongDoubleSummation) {
    // The dense part g = 100..400 crosses the switch from outward summation to the trapezoid rule
    // (peak width 15, g ≈ 225); no jump may appear there.
    std::vector<double> gs;
    for (double g = 0.013; g < 100.0; g *= 1.09) gs.push_back(g);
    for (double g = 100.0; g <= 400.0; g += 0.75) gs.push_back(g);
    for (double g = 400.0; g <= 9000.0; g *= 1.21) gs.push_back(g);
    double worst = 0.0;
    std::string worst_at;
    for (double g : gs) {
        for (double X : {0.0, 0.37, 12.0, 450.0}) {
            for (bool gaussian : {true, false}) {
                const long double ref = long_double_sum(gaussian, g, X);
                const double s =
                    gaussian ? gaussian_series_sum(g, X) : exponential_series_sum(g, X);
                const double err = relative_error(s, ref);
                if (!(err <= worst)) {
                    worst = err;
                    worst_at = (gaussian ? "gaussian g=" : "exponential g=") + std::to_string(g) +
                               " X=" + std::to_string(X);
                }
            }
        }
    }
    // long double accumulates ~n·1e−19 over n ≲ 1e4 terms.
    EXPECT_LE(worst, 1e-12) << "worst at " << worst_at;
}

TEST(SeriesMonotonicity, DecreasingInXAndSumsBoundedByPoissonMass) {
    for (double g : {1e-4, 0.2, 1.0, 8.0, 90.0, 500.0, 4e3, 2e5}) {
        double prev_G = std::numeric_limits<double>::infinity(), prev_E = prev_G;
        for (double X = 0.0; X <= 1e4; X = X == 0.0 ? 1e-3 : X * 3.0) {
            const double sG = gaussian_series_sum(g, X), sE = exponential_series_sum(g, X);
            EXPECT_LT(sG, prev_G) << "g=" << g << " X=" << X;
            EXPECT_LT(sE, prev_E) << "g=" << g << " X=" << X;
            prev_G = sG;
            prev_E = sE;
        }
        // Each summand is ≤ e^{−g} gⁿ/n!, so both sums are ≤ P(N ≥ 1) = 1 − e^{−g}.
        EXPECT_LE(gaussian_series_sum(g, 0.0), -std::expm1(-g) * (1 + 1e-15));
        EXPECT_LE(exponential_series_sum(g, 0.0), -std::expm1(-g) * (1 + 1e-15));
    }
}

TEST(SeriesLimits, SmallGIsFirstTermAndZeroGIsZero) {
    // g → 0: S = e^{−g} [g f(1) + g²/2 f(2) + g³/6 f(3)] (1 + O(g³ e^{X/5})). The first term is
    // the slightly-rough form; the second (relative size g e^{X/8}/4, resp.
    // g ((1+X)/(4+X))^{3/2}) is what Auto compares with its tolerance.
    for (double X : {0.0, 1.0, 30.0}) {
        for (double g : {1e-9, 1e-7, 1e-5}) {
            auto fG = [X](double n) { return std::exp(-X / (4.0 * n)) / n; };
            auto fE = [X](double n) { return n / std::pow(n * n + X, 1.5); };
            const double gauss3 =
                std::exp(-g) * (g * fG(1) + g * g / 2.0 * fG(2) + g * g * g / 6.0 * fG(3));
            const double expo3 =
                std::exp(-g) * (g * fE(1) + g * g / 2.0 * fE(2) + g * g * g / 6.0 * fE(3));
            EXPECT_NEAR(gaussian_series_sum(g, X) / gauss3, 1.0, 1e-13) << g << " " << X;
            EXPECT_NEAR(exponential_series_sum(g, X) / expo3, 1.0, 1e-13) << g << " " << X;
            // The one-term form alone is off by the second term's relative size.
            EXPECT_NEAR(gaussian_series_sum(g, X) / (std::exp(-g) * g * fG(1)) - 1.0,
                        g / 2.0 * fG(2) / fG(1), 1e-13 + g * g * fG(3) / fG(1));
        }
    }
    EXPECT_EQ(gaussian_series_sum(0.0, 5.0), 0.0);
    EXPECT_EQ(exponential_series_sum(0.0, 5.0), 0.0);
}

// Far outside the diffuse lobe the sums underflow to 0 (an expected physical zero): never inf,
// NaN or a hang. Run in a forked child with an alarm so that a hang fails the test in 5 s
// instead of blocking the suite.
TEST(SeriesLimits, ExtremeInputsGiveFiniteNonNegativeValues) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    for (double g : {1e-300, 1e-6, 1.0, 745.0, 1e7}) {
        for (double X : {0.0, 1e-300, 1e6, 1e12, 1e24, 1e30, 1e300}) {
            EXPECT_EXIT(
                {
                    alarm(5);
                    const double sG = gaussian_series_sum(g, X);
                    const double sE = exponential_series_sum(g, X);
                    const bool ok =
                        std::isfinite(sG) && sG >= 0.0 && std::isfinite(sE) && sE >= 0.0;
                    if (!ok) std::fprintf(stderr, "S_G = %g, S_E = %g\n", sG, sE);
                    std::_Exit(ok ? 0 : 1);
                },
                ::testing::ExitedWithCode(0), "")
                << "g = " << g << ", T2_vxy2 = " << X;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Bad input.

template <class Fn>
void expect_invalid(Fn fn, const std::string& must_name, const std::string& what) {
    try {
        fn();
        ADD_FAILURE() << what << ": no exception";
    } catch (const roughscope::InvalidArgument& e) {
        // Messages start with the input's name ("g = -1 is invalid: ...").
        EXPECT_EQ(std::string(e.what()).rfind(must_name, 0), 0u)
            << what << ": message '" << e.what() << "' does not start with " << must_name;
    } catch (const std::exception& e) {
        ADD_FAILURE() << what << ": wrong exception type: " << e.what();
    }
}

TEST(SeriesBadInput, NegativeOrNonFiniteArgumentsThrowInvalidArgument) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    using SumFn = double (*)(double, double);
    for (const auto& entry :
         {std::pair<const char*, SumFn>{"gaussian", &gaussian_series_sum},
          std::pair<const char*, SumFn>{"exponential", &exponential_series_sum}}) {
        const std::string what = entry.first;
        const SumFn sum = entry.second;
        expect_invalid([&] { sum(-1.0, 0.0); }, "g", what + " g=-1");
        expect_invalid([&] { sum(-1e-300, 0.0); }, "g", what + " g=-1e-300");
        expect_invalid([&] { sum(nan, 0.0); }, "g", what + " g=nan");
        expect_invalid([&] { sum(inf, 0.0); }, "g", what + " g=inf");
        expect_invalid([&] { sum(1.0, -0.5); }, "T2_vxy2", what + " X=-0.5");
        expect_invalid([&] { sum(1.0, nan); }, "T2_vxy2", what + " X=nan");
        expect_invalid([&] { sum(1.0, inf); }, "T2_vxy2", what + " X=inf");
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Every finite g: the summation and the large-g expansion (the very-rough limit × (1 + R1/g)).

// At tiny g the sum is its first term e^{−g} g h(1) (n = 1 dominates by a factor 1/g): the
// small-g early exit once compared only the terms n ≥ 5 with the underflow threshold and gave 0.
TEST(SeriesEveryG, TinyGIsTheFirstTermNotZero) {
    for (double g : {1e-300, 1e-200, 1e-100, 1e-30}) {
        for (double X : {0.0, 1.0, 10.0}) {
            EXPECT_NEAR(gaussian_series_sum(g, X) / (g * std::exp(-X / 4.0)), 1.0, 1e-12) << g;
            EXPECT_NEAR(exponential_series_sum(g, X) / (g / std::pow(1.0 + X, 1.5)), 1.0, 1e-12)
                << g;
        }
    }
    EXPECT_GT(gaussian_series_sum(1e-320, 0.0), 0.0);  // subnormal g: still its first term
}

// Large g: S/L − 1 = R1/g + O(1/g²) with L the g → ∞ limit (Eq. 4: e^{−c}/g, c = a/g; and
// 1/(g²(1+β)^{3/2}), β = b/g², for the exponential series). Near g = 1e15 the summation gave 0.
TEST(SeriesEveryG, LargeGFollowsTheVeryRoughLimitWithItsFirstCorrection) {
    for (double g : {1e8, 1e13, 1.6716e15, 1e20, 1e100, 1e300}) {
        for (double c : {0.0, 0.5, 3.0}) {
            const double sG = gaussian_series_sum(g, 4.0 * c * g);
            const double LG = std::exp(-c) / g;
            EXPECT_NEAR(sG / LG - 1.0, (c * c / 2 - 2 * c + 1) / g, 1e-14) << g << " " << c;
            if (c * g * g > 1.7e308) continue;
            const double sE = exponential_series_sum(g, c * g * g);
            const double LE = 1.0 / g / g / std::pow(1.0 + c, 1.5);
            if (LE < 1e-300) continue;
            EXPECT_NEAR(sE / LE - 1.0, 3.0 * (2 - 3 * c) / (2 * (1 + c) * (1 + c)) / g, 1e-14)
                << g << " " << c;
        }
    }
}

TEST(SeriesEveryG, MethodAndBoundAreReported) {
    const auto small = roughscope::diffuse_series(Correlation::Gaussian, 3.0, 1.0);
    EXPECT_EQ(small.method, roughscope::DiffuseMethod::Summation);
    EXPECT_GT(small.relative_error_bound, 0.0);
    EXPECT_LE(small.relative_error_bound, 1e-12);
    const auto large = roughscope::diffuse_series(Correlation::Exponential, 1e15, 1e30);
    EXPECT_EQ(large.method, roughscope::DiffuseMethod::LargeGExpansion);
    EXPECT_GT(large.relative_error_bound, 0.0);
    EXPECT_LE(large.relative_error_bound, 1e-14);
    // On both sides of the switch (summation up to ~1e7, expansion beyond) the value follows
    // the expansion to second order (c = a/g = 1/4: R1 = 17/32, R2 = c⁴/8 − 11c³/6 + 15c²/2 −
    // 9c + 2) within the reported bound.
    const double c = 0.25, R1 = c * c / 2 - 2 * c + 1;
    const double R2 = c * c * c * c / 8 - 11 * c * c * c / 6 + 15 * c * c / 2 - 9 * c + 2;
    for (double g : {1e5, 1e6, 1e7, 1e9}) {
        const auto s = roughscope::diffuse_series(Correlation::Gaussian, g, 4.0 * c * g);
        const double expansion = std::exp(-c) / g * (1.0 + R1 / g + R2 / (g * g));
        EXPECT_NEAR(s.value / expansion, 1.0, s.relative_error_bound + 1e-14) << g;
    }
}

// The B–K model at metre scale (σ = 2 m, T = 4 m, g = 1.67e15): the default Auto
// regime equals the very-rough form (Eq. 4) and says it used the expansion.
TEST(SeriesEveryG, ModelAtMetreScaleUsesTheExpansion) {
    using namespace roughscope;
    const Geometry geom = make_geometry(deg_to_rad(30), deg_to_rad(20), deg_to_rad(45));
    const ScatteredPower p = mean_scattered_power(geom, Surface{2e6, 4e6, Correlation::Gaussian});
    ModelOptions vr;
    vr.regime = Regime::VeryRough;
    const ScatteredPower q =
        mean_scattered_power(geom, Surface{2e6, 4e6, Correlation::Gaussian}, vr);
    EXPECT_EQ(p.regime, Regime::Series);
    EXPECT_EQ(p.method, DiffuseMethod::LargeGExpansion);
    EXPECT_NEAR(p.diffuse / q.diffuse, 1.0, 1e-14);
    EXPECT_NEAR(p.diffuse, 2.5061086778e-8, 1e-17);
    EXPECT_EQ(q.method, DiffuseMethod::ClosedForm);
}

TEST(SeriesEveryG, LengthsOutsideTheRangeThrowNamingThem) {
    using namespace roughscope;
    const Geometry geom = make_geometry(deg_to_rad(30), deg_to_rad(20), deg_to_rad(45));
    expect_invalid(
        [&] {
            mean_scattered_power(geom, Surface{1e300, 1.0});
        },
        "sigma = 1e+300 um", "huge sigma");
    ModelOptions o;
    o.patch_x_um = 5e-324;
    expect_invalid(
        [&] {
            mean_scattered_power(geom, Surface{0.1, 1.0}, o);
        },
        "patch_x", "subnormal patch");
}

// ---------------------------------------------------------------------------------------------
// Quadrature: agreement with the series inside its documented domain, InvalidArgument outside.

TEST(Quadrature, AgreesWithTheSeriesInsideItsDomain) {
    using namespace roughscope;
    for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        for (auto [g, w] : {std::pair{1e-3, 0.5},
                            {0.5, 1.0},
                            {10.0, 5.0},
                            {1e3, 3.0},
                            {1e4, 100.0},
                            {1e4, 0.0},
                            {50.0, 50.0}}) {
            const double vxy2 = (w / 2.0) * (w / 2.0);  // T = 2
            const double q = diffuse_power_quadrature(c, 0.8, 2.0, 1e4, g, vxy2);
            const double s = c == Correlation::Gaussian
                                 ? diffuse_power_gaussian_series(0.8, 2.0, 1e4, g, vxy2)
                                 : diffuse_power_exponential_series(0.8, 2.0, 1e4, g, vxy2);
            const double p = c == Correlation::Gaussian ? 1.0 : 2.0;
            const double scale =
                2 * kPi / 1e4 * 0.8 * 4.0 * -std::expm1(-g) / std::pow(std::max(g, 1.0), p);
            EXPECT_GE(q, 0.0);
            EXPECT_LE(std::abs(q - s), 1e-12 * scale) << to_string(c) << " g = " << g;
        }
    }
}

TEST(Quadrature, OutsideItsDomainThrowsInvalidArgument) {
    using namespace roughscope;
    for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        expect_invalid([&] { diffuse_power_quadrature(c, 1.0, 2.0, 1.0, 2e4, 1.0); }, "g = 20000",
                       "g above the domain");
        expect_invalid([&] { diffuse_power_quadrature(c, 1.0, 2.0, 1.0, 1e300, 1.0); },
                       "g = 1e+300", "huge g (was NaN)");
        expect_invalid([&] { diffuse_power_quadrature(c, 1.0, 2.0, 1.0, 1.0, 1e6); },
                       "T v_xy = 2000", "T v_xy above the domain (was seconds)");
        expect_invalid([&] { diffuse_power_quadrature(c, 1e300, 1e300, 1e-300, 1.0, 0.0); },
                       "(2 pi/A) F2 T^2", "overflowing prefactor");
    }
}
