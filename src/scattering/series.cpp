// The Poisson-weighted series of the diffuse B–K term (Eq. 2 and the exact exponential series).
//
//   S = Σ_{n≥1} t(n),  t(n) = e^{−g} gⁿ/n! · h(n)
//   Gaussian:    h(n) = exp(−a/n)/n,        a = T² v_xy²/4   (Eq. 2)
//   Exponential: h(n) = n/(n² + b)^{3/2},   b = T² v_xy²
//
// Algorithm (docs/exponential-correlation.md has the derivation):
//  1. log t(x) is evaluated for real x ≥ 1 without cancellation through Loader's saddle-point form
//     of the Poisson log-pmf: log(e^{−g} g^x/Γ(x+1)) = −½ log(2πx) − stirlerr(x) − bd0(x, g).
//  2. For n ≥ 5 the sequence t(n) is log-concave in both cases (the ratio t(n+1)/t(n) decreases),
//     so it has one peak m, found by a doubling-then-bisection search that starts at n ≈ g.
//  3. Narrow peaks (width s = (−d² log t)^{−1/2} < kTrapezoidMinWidth): terms are summed
//     outward from m with the ratio recurrence t(n+1) = t(n)·r(n), scaled by t(m) so nothing
//     overflows; each side stops when the geometric bound on its remaining tail (valid because
//     the ratio is monotone) is below kRelTol of the sum. Terms n = 1..4 (where the exponential
//     case need not be log-concave) are always added explicitly, in log space.
//  4. Wide peaks (s ≥ kTrapezoidMinWidth, i.e. g ≳ 200): by Poisson summation the sum over the
//     integers equals the integral of the analytic continuation t(x) up to O(exp(−2π²s²)), and the
//     trapezoid rule with step Δ = kStepPerWidth·s converges to that integral with error
//     O(exp(−2π²/kStepPerWidth²)) ≈ e^{−55}. ~30 evaluations replace ~17·√g terms.
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"

namespace roughscope {
namespace {

constexpr double kRelTol = 1e-17;
constexpr double kTrapezoidMinWidth = 15.0;
constexpr double kStepPerWidth = 0.6;
constexpr double kMaxN = 1e15;  // no physical series peaks beyond this many terms
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
// The large-g expansion replaces the summation where its bound is the smaller one, never below
// kExpansionMinG, always above kSeriesMaxG (where x ± 1 loses integer resolution in the search).
constexpr double kExpansionMinG = 1e4;
constexpr double kSeriesMaxG = 1e13;
constexpr double kHalfLog2Pi = 0.91893853320467274178032973640561764;  // ½ log(2π)

// stirlerr(n) = log n! − (n + ½) log n + n − ½ log(2π), n = 0..15, from mpmath at 40 digits.
constexpr double kStirlErr[16] = {
    0.0,
    0.08106146679532725822,
    0.041340695955409294094,
    0.027677925684998339149,
    0.020790672103765093112,
    0.016644691189821192163,
    0.013876128823070747999,
    0.011896709945891770095,
    0.010411265261972096497,
    0.0092554621827127329177,
    0.0083305634333628712565,
    0.007573675487951840795,
    0.0069428401072095298657,
    0.0064089941880042070684,
    0.0059513701127588477356,
    0.005554733551962801371,
};

// Error of Stirling's formula for log Γ(x+1), x > 0.
double stirlerr(double x) {
    if (x <= 15.0) {
        const double n = std::floor(x);
        if (n == x) return kStirlErr[static_cast<int>(n)];
        return std::lgamma(x + 1.0) - (x + 0.5) * std::log(x) + x - kHalfLog2Pi;
    }
    // Stirling series: 1/12x − 1/360x³ + 1/1260x⁵ − 1/1680x⁷ + 1/1188x⁹ − 691/360360x¹¹.
    const double y = 1.0 / (x * x);
    return (1.0 / 12 -
            y * (1.0 / 360 -
                 y * (1.0 / 1260 - y * (1.0 / 1680 - y * (1.0 / 1188 - y * (691.0 / 360360)))))) /
           x;
}

// bd0(x, m) = x log(x/m) + m − x ≥ 0, without cancellation when x ≈ m (Loader 2000).
double bd0(double x, double m) {
    if (std::abs(x - m) < 0.1 * (x + m)) {
        const double v = (x - m) / (x + m), v2 = v * v;
        double s = (x - m) * v, ej = 2.0 * x * v;
        for (int j = 1; j < 1000; ++j) {
            ej *= v2;
            const double s1 = s + ej / (2 * j + 1);
            if (s1 == s) return s1;
            s = s1;
        }
        return s;
    }
    return x * (std::log(x) - std::log(m)) + m - x;  // x/m would overflow for subnormal m
}

// log(e^{−g} g^x / Γ(x+1)) for x ≥ 1, g > 0.
double log_poisson(double x, double g) {
    return -0.5 * std::log(2.0 * std::numbers::pi * x) - stirlerr(x) - bd0(x, g);
}

// Each summand provides log t(x) for real x ≥ 1 and the ratio t(n+1)/t(n), which is cheap
// (one exp or one sqrt) and is used to walk outward from the peak in the direct path.
struct GaussianTerm {
    double g, a;
    double operator()(double x) const { return log_poisson(x, g) - std::log(x) - a / x; }
    double ratio(double n) const {  // g n/(n+1)² · exp(a/(n(n+1)))
        const double n1 = n + 1.0;
        return g * n / (n1 * n1) * std::exp(a / (n * n1));
    }
};

struct ExponentialTerm {
    double g, b;
    double operator()(double x) const {
        return log_poisson(x, g) + std::log(x) - 1.5 * std::log(x * x + b);
    }
    double ratio(double n) const {  // (g/n) · ((n² + b)/((n+1)² + b))^{3/2}
        const double q = (n * n + b) / ((n + 1.0) * (n + 1.0) + b);
        return g / n * q * std::sqrt(q);
    }
};

template <class LogTerm>
double poisson_series(const LogTerm& lt, double g) {
    constexpr int kLow = 5;  // the sequence is log-concave from here on (both cases)
    // Peak of t(n) over n ≥ kLow: d(n) = lt(n+1) − lt(n) is decreasing there.
    auto d = [&](double n) { return lt(n + 1.0) - lt(n); };
    double lo, hi;  // d(lo) > 0 ≥ d(hi) once bracketed
    double start = std::max<double>(kLow, std::floor(g));
    if (start > kMaxN) start = kMaxN;
    if (d(start) > 0.0) {
        lo = start;
        double step = 1.0;
        hi = start + step;
        while (d(hi) > 0.0 && hi < kMaxN) {
            lo = hi;
            step *= 2.0;
            hi = start + step;
        }
    } else {
        hi = start;
        double step = 1.0;
        lo = start - step;
        while (lo > kLow && d(lo) <= 0.0) {
            hi = lo;
            step *= 2.0;
            lo = std::max<double>(kLow, start - step);
        }
        if (lo <= kLow && d(kLow) <= 0.0) hi = lo = kLow;
    }
    for (int it = 0; hi - lo > 1.0 && it < 200; ++it) {
        const double mid = std::floor(0.5 * (lo + hi));
        if (mid <= lo || mid >= hi) break;  // beyond integer resolution of doubles
        (d(mid) > 0.0 ? lo : hi) = mid;
    }
    const double m = hi;  // first n with d(n) ≤ 0: the peak
    const double lt_m = lt(m);
    // Every term is ≤ the larger of the peak term and the terms n < kLow (which dominate for
    // small g), and there are fewer than kMaxN (≈ e^35) that matter, so a largest term below
    // e^{−800} means the sum underflows: an expected physical zero. This also keeps absurd
    // inputs (T·v_xy ~ 1e12) from summing rounding noise.
    double low[kLow];
    double ref = lt_m;
    for (int n = 1; n < kLow; ++n) ref = std::max(ref, low[n] = lt(n));
    if (!(ref > -800.0)) return 0.0;

    // Width of the peak from the discrete second difference.
    const double curv = m > kLow ? lt(m + 1.0) - 2.0 * lt_m + lt(m - 1.0) : -1.0;
    const double width = curv < 0.0 ? 1.0 / std::sqrt(-curv) : 0.0;

    double sum = 0.0;  // in units of t(m)
    if (width >= kTrapezoidMinWidth && lt(kLow) - lt_m < -80.0) {
        // Trapezoid rule on the analytic continuation (see file comment).
        const double step = kStepPerWidth * width;
        sum = 1.0;
        for (double x = m + step; x < m + 1e4 * step; x += step) {
            const double t = std::exp(lt(x) - lt_m);
            sum += t;
            if (t < kRelTol * sum) break;
        }
        for (double x = m - step; x >= kLow; x -= step) {
            const double t = std::exp(lt(x) - lt_m);
            sum += t;
            if (t < kRelTol * sum) break;
        }
        sum *= step;
    } else {
        // Terms n = 1..kLow−1 explicitly in log space; from the peak outward by the ratio
        // recurrence t(n±1) = t(n)·r^{±1} (terms scaled by t(m), so they never overflow; the
        // rounding grows like (number of terms)·ε ≲ 1e−13 because this path sees < ~300 terms).
        for (int n = 1; n < kLow; ++n) sum += std::exp(low[n] - ref);
        double walk = 1.0;  // Σ t(n)/t(m) over n ≥ kLow
        double t = 1.0;
        for (double n = m; n < m + 1e8; n += 1.0) {
            const double r = lt.ratio(n);  // t(n+1)/t(n), decreasing in n
            t *= r;
            walk += t;
            if (t == 0.0 || (r < 1.0 && t * r / (1.0 - r) < kRelTol * walk)) break;
        }
        t = 1.0;
        for (double n = m - 1.0; n >= kLow; n -= 1.0) {
            const double rho = 1.0 / lt.ratio(n);  // t(n)/t(n+1), decreasing going down
            t *= rho;
            walk += t;
            if (t == 0.0 || (rho < 1.0 && t * rho / (1.0 - rho) < kRelTol * walk)) break;
        }
        sum += walk * std::exp(lt_m - ref);
        return std::exp(ref + std::log(sum));
    }
    return std::exp(lt_m + std::log(sum));
}

void check_series_args(double g, double T2_vxy2) {
    check::non_negative("g", g);
    check::non_negative("T2_vxy2 (T^2 v_xy^2)", T2_vxy2);
}

// Relative error of the summation (steps 3–4 above), measured against 40-digit references
// (tests/cpp/scattering/test_series.cpp, tests/python/test_series.py): ≲ 1e−13 up to g = 1e7
// (≲ ε·|ln S| ≤ 1.7e−13 for the smallest S, which are evaluated in log space), growing with g
// beyond (the log-space terms lose digits as log x grows); stated with margin.
double summation_error_bound(double g) { return 2e-13 + 1e-21 * g; }

// Large-g expansion (docs/exponential-correlation.md, "Large g"): with N ~ Poisson(g),
// S = E[h(N)] and h(x) = f(x/g)/g^p, expanding h about the mean with the Poisson central moments
// (μ2 = μ3 = g, μ4 = 3g² + g, μ5 = 10g² + g, μ6 = 15g³ + ...) gives
//   S = h(g) [1 + R1/g + R2/g² + R3/g³ + ...],
//   R1 = f″/2f,  R2 = (f‴/6 + f⁗/8)/f,  R3 = (f⁗/24 + f⁽⁵⁾/12 + f⁽⁶⁾/48)/f  at u = 1.
// h(g) is the very-rough limit (Eq. 4; the series limit for the exponential case). The value
// returned keeps 1 + R1/g; the bound is twice the next two terms plus the rounding of the
// exponent. (The N = 0 term, e^{−g}, is far below it wherever the expansion is used.)
struct Expansion {
    double limit, R1, R2, R3, rounding;
};

// Gaussian: f(u) = exp(−c/u)/u, c = a/g = T²v_xy²/(4g) (Eq. 4's exponent T²v_xy²/4σ²v_z²).
Expansion gaussian_expansion(double g, double a) {
    const double c = a / g;
    const double c2 = c * c, c3 = c2 * c, c4 = c2 * c2;
    return {std::exp(-c) / g, c2 / 2 - 2 * c + 1, c4 / 8 - 11 * c3 / 6 + 15 * c2 / 2 - 9 * c + 2,
            c4 * c2 / 48 - 2 * c4 * c / 3 + 22 * c4 / 3 - 34 * c3 + 131 * c2 / 2 - 44 * c + 6,
            8.0 * kEpsilon * (1.0 + c)};
}

// Exponential: f(u) = u/(u² + β)^{3/2}, β = b/g² (the series limit g/(g² + b)^{3/2}).
Expansion exponential_expansion(double g, double b) {
    const double beta = b / g / g, p = 1.0 + beta;
    const double b2 = beta * beta, b3 = b2 * beta, b4 = b2 * b2;
    const double p2 = p * p, p4 = p2 * p2;
    return {1.0 / g / g / (p * std::sqrt(p)), -3.0 * (3.0 * beta - 2.0) / (2.0 * p2),
            -(12 * b3 - 309 * b2 + 536 * beta - 88) / (8 * p4),
            5 * (90 * b4 - 1775 * b3 + 4656 * b2 - 2328 * beta + 160) / (16 * p4 * p2),
            32.0 * kEpsilon};
}

template <class Summation>
SeriesResult evaluate_series(const Expansion& e, double g, Summation&& summation) {
    const double expansion_bound =
        2.0 * (std::abs(e.R2) / g / g + std::abs(e.R3) / g / g / g) + e.rounding;
    if (g > kSeriesMaxG || (g >= kExpansionMinG && expansion_bound <= summation_error_bound(g)))
        return {e.limit * (1.0 + e.R1 / g), DiffuseMethod::LargeGExpansion, expansion_bound};
    return {summation(), DiffuseMethod::Summation, summation_error_bound(g)};
}

}  // namespace

SeriesResult diffuse_series(Correlation correlation, double g, double T2_vxy2) {
    check_series_args(g, T2_vxy2);
    if (g == 0.0) return {0.0, DiffuseMethod::Summation, 0.0};
    switch (correlation) {
        case Correlation::Gaussian: {
            const double a = T2_vxy2 / 4.0;
            return evaluate_series(gaussian_expansion(g, a), g, [&] {
                return poisson_series(GaussianTerm{g, a}, g);
            });
        }
        case Correlation::Exponential:
            return evaluate_series(exponential_expansion(g, T2_vxy2), g, [&] {
                return poisson_series(ExponentialTerm{g, T2_vxy2}, g);
            });
    }
    throw InvalidArgument("diffuse_series: correlation " +
                          std::to_string(static_cast<int>(correlation)) + " is not defined");
}

double diffuse_series_sum_naive(Correlation correlation, double g, double T2_vxy2, int max_terms) {
    double sum = 0.0, power = 1.0;  // gⁿ/n!
    for (int n = 1; n <= max_terms; ++n) {
        power *= g / n;
        sum += power * series_term_weight(correlation, n, T2_vxy2);
    }
    return std::exp(-g) * sum;
}

}  // namespace roughscope
