// The correlation function of the surface heights as one dimension of the models (paper §3.1):
// every quantity that depends on it is a function of a `Correlation` value defined here, so that
// a new correlation function is a new row of this file (and of the series and the batch kernel
// in src/scattering), not a new copy of every caller.
//
//   Gaussian     C(τ) = σ² exp(−τ²/T²)   Eq. 2 (series), 3 (slightly rough), 4 (very rough), 16–17
//   exponential  C(τ) = σ² exp(−|τ|/T)   the exact series, Eq. 5 (very rough), 18–19
//
// Notation (beckmann.hpp): u = τ/T; b = T² v_xy²; the very-rough argument t² = T² v_xy²/(σ² v_z²)
// (= q_xy²/((σ/T)² q_z²), q = v/k); at normal view a = q_xy²/q_z² per incidence angle.
// Everything here is a small pure function without input checks; the validated entry points are
// in beckmann.hpp, retro.hpp and estimation.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>

namespace roughscope {

enum class Correlation { Gaussian, Exponential };

// Every correlation function, in the order of the enum (loops over correlations, result arrays).
inline constexpr std::array<Correlation, 2> kCorrelations{Correlation::Gaussian,
                                                          Correlation::Exponential};
inline constexpr std::size_t kCorrelationCount = kCorrelations.size();

constexpr std::size_t index_of(Correlation c) { return static_cast<std::size_t>(c); }
constexpr bool is_valid(Correlation c) { return index_of(c) < kCorrelationCount; }

// The names and constants of one correlation function.
struct CorrelationInfo {
    Correlation correlation;
    std::string_view name;       // "gaussian": to_string/parse_correlation and JSON key suffixes
    std::string_view adjective;  // "Gaussian": messages ("Gaussian correlation")
    std::string_view letter;     // "G": the paper's σ/T_G and B–K(G) (§5)
    std::string_view very_rough_equation;  // the very-rough closed form, "Eq. 4"
    std::string_view ratio_equation;       // its two-angle brightness ratio, "Eq. 16"
    std::string_view inverse_equation;     // the ratio solved for σ/T, "Eq. 17"
    // D = diffuse_prefactor · (T²/A) F² S(g, b) with S the Poisson-weighted series (Eq. 2).
    double diffuse_prefactor;
    // The very-rough closed form equals the g → ∞ limit of the exact series (Eq. 4 does; Eq. 5
    // as published does not: docs/exponential-correlation.md).
    bool closed_form_is_series_limit;
    // C(x, y) = C(x) C(y) (the surface generator sums the periodised ACF per axis).
    bool separable;
    // Caron's θK and ξK (§3.5) are derived for this correlation function.
    bool caron_formulas;
    // T has a closed form from two slightly-rough brightnesses at normal view (Eq. 15, from
    // Eq. 3); otherwise the two-geometry solver is used.
    bool slightly_rough_inverse;
};

inline constexpr std::array<CorrelationInfo, kCorrelationCount> kCorrelationInfo{{
    {Correlation::Gaussian, "gaussian", "Gaussian", "G", "Eq. 4", "Eq. 16", "Eq. 17",
     std::numbers::pi, true, true, true, true},
    {Correlation::Exponential, "exponential", "exponential", "E", "Eq. 5", "Eq. 18", "Eq. 19",
     2.0 * std::numbers::pi, false, false, false, false},
}};

// (An invalid value — checked with is_valid at the API boundaries — reads the first row.)
constexpr const CorrelationInfo& info(Correlation c) {
    return kCorrelationInfo[is_valid(c) ? index_of(c) : 0];
}

// A JSON key or column name for one correlation: `stem` + "_" + name ("sigma_over_T_gaussian").
inline std::string correlation_key(std::string_view stem, Correlation c) {
    std::string key(stem);
    key.append("_").append(info(c).name);
    return key;
}

// "gaussian or exponential": the names for messages listing the valid values.
inline std::string correlation_names_text() {
    std::string names;
    for (const CorrelationInfo& c : kCorrelationInfo)
        names.append(names.empty()                           ? ""
                     : c.correlation == kCorrelations.back() ? " or "
                                                             : ", ")
            .append(c.name);
    return names;
}

// One value per correlation function, indexed by Correlation.
template <class T>
struct PerCorrelation {
    std::array<T, kCorrelationCount> values{};
    T& operator[](Correlation c) { return values[index_of(c)]; }
    const T& operator[](Correlation c) const { return values[index_of(c)]; }
};

// ---------------------------------------------------------------------------------------------
// The correlation function and its spectrum.

// ρ(u) = C(τ)/σ², u = |τ|/T ≥ 0 (§3.1): exp(−u²) or exp(−u).
inline double acf(Correlation c, double u) {
    switch (c) {
        case Correlation::Gaussian:
            return std::exp(-u * u);
        case Correlation::Exponential:
            return std::exp(-u);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// u beyond which ρ(u) < e^{−L} (L = log_inverse_tolerance > 0): √L or L.
inline double acf_cutoff_over_T(Correlation c, double log_inverse_tolerance) {
    switch (c) {
        case Correlation::Gaussian:
            return std::sqrt(log_inverse_tolerance);
        case Correlation::Exponential:
            return log_inverse_tolerance;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// Width (in u) of the peak of e^{g ρ(u)} − 1 at u = 0, the integrand of the diffuse Kirchhoff
// integral (§3.1): 1/√g (Gaussian) or 1/g (exponential), capped at 1 for g < 1.
inline double diffuse_kernel_width_over_T(Correlation c, double g) {
    switch (c) {
        case Correlation::Gaussian:
            return 1.0 / std::sqrt(std::max(g, 1.0));
        case Correlation::Exponential:
            return 1.0 / std::max(g, 1.0);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// Isotropic 2-D power spectrum of ρ over T²: W(κ) = 2π ∫₀^∞ ρ(u) J0(κu) u du, κ² = kT2 =
// (k T)² — π exp(−κ²/4) (the n = 1 term of Eq. 2, Eq. 3) or 2π/(1 + κ²)^{3/2}.
inline double power_spectrum(Correlation c, double kT2) {
    switch (c) {
        case Correlation::Gaussian:
            return std::numbers::pi * std::exp(-kT2 / 4.0);
        case Correlation::Exponential:
            return 2.0 * std::numbers::pi / std::pow(1.0 + kT2, 1.5);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// The exact series D = diffuse_prefactor (T²/A) F² e^{−g} Σ_{n≥1} gⁿ/n! h(n) (Eq. 2).

// h(n), b = T² v_xy²: exp(−b/(4n))/n (Eq. 2) or n/(n² + b)^{3/2} (the order-0 Hankel transform
// of ρⁿ = e^{−nu}). The g → ∞ limit of the series is h(g).
inline double series_term_weight(Correlation c, double n, double b) {
    switch (c) {
        case Correlation::Gaussian:
            return std::exp(-b / (4.0 * n)) / n;
        case Correlation::Exponential:
            return n / std::pow(n * n + b, 1.5);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// The second term of the series over the first, (g/2) h(2)/h(1), which bounds every omitted
// term of the one-term form (Eq. 3): (g/4) e^{b/8} or g ((1 + b)/(4 + b))^{3/2}.
inline double second_term_ratio(Correlation c, double g, double b) {
    switch (c) {
        case Correlation::Gaussian:
            return g / 4.0 * std::exp(b / 8.0);
        case Correlation::Exponential:
            return g * std::pow((1.0 + b) / (4.0 + b), 1.5);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// The very-rough closed forms: D = diffuse_prefactor T²/(A σ²) F²/v_z² P(t²) (Eq. 4, Eq. 5).

// P(t²): exp(−t²/4) (Eq. 4) or (1 + t²)^{−3/2} (Eq. 5).
inline double very_rough_profile(Correlation c, double t2) {
    switch (c) {
        case Correlation::Gaussian:
            return std::exp(-0.25 * t2);
        case Correlation::Exponential: {
            const double w = 1.0 + t2;
            return 1.0 / (w * std::sqrt(w));
        }
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// ln P(t²), finite where P underflows: −t²/4 (Eq. 4) or −(3/2) ln(1 + t²) (Eq. 5).
inline double log_very_rough_profile(Correlation c, double t2) {
    switch (c) {
        case Correlation::Gaussian:
            return -0.25 * t2;
        case Correlation::Exponential:
            return -1.5 * std::log1p(t2);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// d ln P / d ln(σ/T) (t² ∝ (σ/T)^{−2}): t²/2 (Eq. 4) or 3t²/(1 + t²) (Eq. 5).
inline double d_log_very_rough_profile_d_log_slope(Correlation c, double t2) {
    switch (c) {
        case Correlation::Gaussian:
            return 0.5 * t2;
        case Correlation::Exponential:
            return 3.0 * t2 / (1.0 + t2);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// The two-angle brightness ratio of §4.2 (viewer on the normal) and its inverse.

// An open interval (lower, upper) of ratios for which an estimator has a solution; upper may be
// +inf. The bounds are the ratios the model produces in its limits (σ/T → ∞ and σ/T → 0).
struct RatioRange {
    double lower = 0.0;
    double upper = 0.0;
    bool contains(double ratio) const { return ratio > lower && ratio < upper; }
};

// The per-angle terms of Eq. 16–19: a = q_xy²/q_z² at θ1 and θ2 (normal view) and
// C = (F1²/q_z1²)/(F2²/q_z2²), the ratio as σ/T → ∞.
struct NormalViewPair {
    double a1 = 0.0, a2 = 0.0;
    double C = 1.0;
};

// Eq. 16 / 18: E1/E2 = C P(a1/(σ/T)²)/P(a2/(σ/T)²).
inline double normal_view_ratio(Correlation c, const NormalViewPair& p, double sigma_over_T) {
    const double m2 = sigma_over_T * sigma_over_T;
    return p.C *
           std::exp(log_very_rough_profile(c, p.a1 / m2) - log_very_rough_profile(c, p.a2 / m2));
}

// The ratios Eq. 16 / 18 take for σ/T in (0, ∞): between C (σ/T → ∞) and C times the limit of
// P(a1 x)/P(a2 x) as x → ∞ — 0 or ∞ (Eq. 16), (a2/a1)^{3/2} (Eq. 18).
inline RatioRange normal_view_ratio_range(Correlation c, const NormalViewPair& p) {
    double limit = std::numeric_limits<double>::quiet_NaN();
    switch (c) {
        case Correlation::Gaussian:
            limit = p.a2 > p.a1 ? std::numeric_limits<double>::infinity() : 0.0;
            break;
        case Correlation::Exponential:
            limit =
                p.a1 > 0.0 ? std::pow(p.a2 / p.a1, 1.5) : std::numeric_limits<double>::infinity();
            break;
    }
    if (p.a2 > p.a1) return {p.C, p.C * limit};
    return {p.a2 > 0.0 ? p.C * limit : 0.0, p.C};
}

// The radicand R of the inverse: σ/T = ½ √R with R = (a2 − a1)/ln κ, κ = (E1/E2)/C (Eq. 17), or
// σ/T = √R with R = (a2 − κ^{2/3} a1)/(κ^{2/3} − 1) (Eq. 19). No solution unless 0 < R < ∞.
inline double ratio_inverse_radicand(Correlation c, const NormalViewPair& p, double E1_over_E2) {
    switch (c) {
        case Correlation::Gaussian: {
            const double log_kappa =
                std::log(E1_over_E2) - std::log(p.C);  // no overflow of E1/E2/C
            return (p.a2 - p.a1) / log_kappa;
        }
        case Correlation::Exponential: {
            const double k13 = std::cbrt(E1_over_E2) / std::cbrt(p.C);  // no overflow of E1/E2/C
            const double k23 = k13 * k13;
            return (p.a2 - k23 * p.a1) / (k23 - 1.0);
        }
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// Eq. 17 / 19: σ/T from E1/E2, or NaN where the ratio has no solution (outside
// normal_view_ratio_range).
inline double sigma_over_T_from_normal_view_ratio(Correlation c, const NormalViewPair& p,
                                                  double E1_over_E2) {
    const double radicand = ratio_inverse_radicand(c, p, E1_over_E2);
    if (!(radicand > 0.0) || !std::isfinite(radicand))
        return std::numeric_limits<double>::quiet_NaN();
    switch (c) {
        case Correlation::Gaussian:
            return 0.5 * std::sqrt(radicand);
        case Correlation::Exponential:
            return std::sqrt(radicand);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// d(σ/T)/d ln(E1/E2) at the solution s = σ/T of Eq. 17 / 19: −s/(2 ln κ) (Eq. 17) or
// (a1 − a2) K/(3 s (K − 1)²), K = κ^{2/3} (Eq. 19).
inline double d_sigma_over_T_d_log_ratio(Correlation c, const NormalViewPair& p, double E1_over_E2,
                                         double s) {
    switch (c) {
        case Correlation::Gaussian:
            return -s / (2.0 * (std::log(E1_over_E2) - std::log(p.C)));
        case Correlation::Exponential: {
            const double k13 = std::cbrt(E1_over_E2) / std::cbrt(p.C);
            const double K = k13 * k13;
            return (p.a1 - p.a2) * K / (3.0 * s * (K - 1.0) * (K - 1.0));
        }
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// What a NoSolution message adds after the valid range of Eq. 17 / 19 (" (kappa = ... must
// exceed 1)", " (the radicand of Eq. 19 is ...)"), or "" (src/scattering/correlation.cpp).
std::string ratio_inverse_no_solution_detail(Correlation c, const NormalViewPair& p,
                                             double E1_over_E2);

// ---------------------------------------------------------------------------------------------
// Numerical choices that follow from the shape of ρ.

// Half-side of the simulated patch in units of T (simulation/kirchhoff.cpp) over which the
// kernel e^{g ρ(u)} − 1 is above `tolerance`/4 of its peak: 6 (Gaussian: ρ(6) = e^{−36}), or
// max(8, ln(4 g/tolerance)) (exponential: ρ decays like e^{−u}, its peak grows with g).
inline double simulation_patch_over_T(Correlation c, double g, double tolerance) {
    switch (c) {
        case Correlation::Gaussian:
            return 6.0;
        case Correlation::Exponential:
            return std::max(8.0, std::log(4.0 * std::max(g, 1.0) / tolerance));
    }
    return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace roughscope
