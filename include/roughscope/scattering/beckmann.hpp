// The Beckmann–Kirchhoff (B–K) mean scattered power, paper §3.1 (Eq. 1–5), with the geometric
// factor and radiometric interpretation of §3.2–3.3 selectable.
//
// P(θi, φi = π, θs, φs) = ρ0² e^{−g} + D                                          (Eq. 1)
//
// Diffuse term D for an isotropic Gaussian height distribution, in every regime:
//  * Gaussian correlation C(τ) = exp(−τ²/T²):
//      Series         Eq. 2  (πT²/A) F² e^{−g} Σ_{n≥1} gⁿ/(n! n) exp(−T² v_xy²/4n)
//      SlightlyRough  Eq. 3  first term of Eq. 2 (g ≪ 1)
//      VeryRough      Eq. 4  (πT²/Aσ²) F²/v_z² exp(−T² v_xy²/(4σ² v_z²))  (g ≫ 1; = limit of Eq. 2)
//  * Exponential correlation C(τ) = exp(−|τ|/T):
//      Series         (2πT²/A) F² e^{−g} Σ_{n≥1} gⁿ/n! · n/(n² + T² v_xy²)^{3/2}
//                     (the exact Kirchhoff series, from Cⁿ = e^{−nτ/T} and the order-0 Hankel
//                     transform; not printed in the paper)
//      SlightlyRough  first term of that series
//      VeryRough      Eq. 5 exactly as published: (2πT²/Aσ²) F²/(v_z² [1 + T²v_xy²/σ²v_z²]^{3/2})
//      VeryRoughSeriesLimit  g → ∞ limit of the exact series: (2πT²/A) F² g/(g² + T²v_xy²)^{3/2}
//    Eq. 5 is NOT the large-g limit of the exact series (docs/exponential-correlation.md); the
//    paper's Figs. 3–4 and Eq. 8, 10, 18, 19 use Eq. 5. Every result reports which one was used.
//
// Units: σ, T, λ, X, Y in µm; P is dimensionless (Beckmann's normalisation to a smooth plate).
#pragma once

#include <cmath>
#include <string_view>

#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope {

enum class Regime {
    Auto,                  // Series when σ, T (and λ) are known; see ModelOptions::auto_tolerance
    Series,                // exact series (Eq. 2, or the exact exponential series)
    SlightlyRough,         // first term only (Eq. 3 for Gaussian)
    VeryRough,             // the paper's very-rough closed forms, Eq. 4 (Gaussian), Eq. 5 (exp.)
    VeryRoughSeriesLimit,  // g → ∞ limit of the exact series (Gaussian: identical to Eq. 4)
};

std::string_view to_string(Correlation c);  // "gaussian", "exponential"
std::string_view to_string(Regime r);       // "auto", "series", "slightly_rough", "very_rough",
                                            // "very_rough_series_limit"
Correlation parse_correlation(std::string_view name);  // throws InvalidArgument listing names
Regime parse_regime(std::string_view name);

// How the diffuse term D was evaluated.
enum class DiffuseMethod {
    ClosedForm,       // the one-term or very-rough closed form of the regime (Eq. 3, 4, 5, ...)
    Summation,        // the series summed (g ≲ 1e7, or where the summation is the more accurate)
    LargeGExpansion,  // the series by its large-g expansion: the very-rough limit × (1 + R1/g)
};
std::string_view to_string(DiffuseMethod m);  // "closed_form", "summation", "large_g_expansion"

// ---------------------------------------------------------------------------------------------
// Dimensionless Poisson-weighted sums (the series without their prefactors), correct for every
// finite g ≥ 0 and T²v_xy² ≥ 0 with a stated relative error bound:
//  * Summation (g ≤ 1e13): summed outward from the peak of the summand, so no term count is
//    fixed and nothing overflows; for wide peaks (g ≳ 200) by the exponentially convergent
//    trapezoid rule on the analytic continuation of the summand (Poisson summation), so the cost
//    stays bounded (~1 µs) however large g is. Relative error ≲ 1e−13 up to g = 1e7 (checked
//    against 40-digit references), bound stated as 2e−13 + 1e−21·g.
//  * Large-g expansion (g ≥ 1e4 where its bound is the smaller, always for g > 1e13): the
//    very-rough limit (Eq. 4; for the exponential case the series limit) times 1 + R1/g, with
//    the bound 2(|R2|/g² + |R3|/g³) + rounding from the next terms (series.cpp,
//    docs/exponential-correlation.md). At g = 1e7 the bound is ~4e−14 inside the lobe.
// Underflow to 0 is an expected physical zero (far outside the diffuse lobe, or g·e^{−a}
// below the smallest double for tiny g).
struct SeriesResult {
    double value = 0.0;
    DiffuseMethod method = DiffuseMethod::Summation;
    double relative_error_bound = 0.0;
};

// S(g, b) = e^{−g} Σ_{n≥1} gⁿ/n! h(n), b = T² v_xy², h = series_term_weight (correlation.hpp):
// exp(−b/4n)/n for the Gaussian (Eq. 2), n/(n² + b)^{3/2} for the exponential correlation.
SeriesResult diffuse_series(Correlation correlation, double g, double T2_vxy2);
inline double diffuse_series_sum(Correlation correlation, double g, double T2_vxy2) {
    return diffuse_series(correlation, g, T2_vxy2).value;
}

// Textbook summation from n = 1 with a fixed number of terms and e^{−g} applied at the end:
// the baseline the benchmarks compare against. Overflows (returns inf/nan) beyond g ≈ 709 and
// is inaccurate when max_terms < ~g + 10√g. Not for production use.
double diffuse_series_sum_naive(Correlation correlation, double g, double T2_vxy2, int max_terms);

// ---------------------------------------------------------------------------------------------
// The individual terms as pure functions (unchecked inputs; F2 = F², vxy2 = v_xy², vz2 = v_z²).

// ρ0 = sinc(vx X) sinc(vy Y) for a 2X × 2Y patch (§3.1); ρ0 = 1 in the specular direction.
inline double specular_amplitude_rho0(double vx, double vy, double X_um, double Y_um) {
    auto sinc = [](double x) {  // → 0 as |x| → ∞ (also where vx·X overflows)
        if (!(std::abs(x) <= 1.7976931348623157e308)) return 0.0;
        return std::abs(x) < 1e-8 ? 1.0 - x * x / 6.0 : std::sin(x) / x;
    };
    return sinc(vx * X_um) * sinc(vy * Y_um);
}

// Coherent term of Eq. 1: ρ0² e^{−g}.
inline double coherent_power(double rho0, double g) { return rho0 * rho0 * std::exp(-g); }

// Eq. 2 (and the exact exponential series): D = prefactor (T²/A) F² S(g, T² v_xy²).
inline double diffuse_power_series(Correlation c, double F2, double T_um, double area_um2, double g,
                                   double vxy2) {
    return info(c).diffuse_prefactor * T_um * T_um / area_um2 * F2 *
           diffuse_series_sum(c, g, T_um * T_um * vxy2);
}

// Eq. 3 (and the first exponential term): the n = 1 term of the series, (T²/A) F² g e^{−g}
// W(T v_xy) with W = power_spectrum.
inline double diffuse_power_slightly_rough(Correlation c, double F2, double T_um, double area_um2,
                                           double g, double vxy2) {
    return T_um * T_um / area_um2 * F2 * g * std::exp(-g) * power_spectrum(c, T_um * T_um * vxy2);
}

// t² = q_xy²/((σ/T)² q_z²) = T² v_xy²/(σ² v_z²), the argument of the very-rough forms: finite
// or +inf for every positive σ/T (never 0/0 or inf/inf): 0 on the specular direction, and from
// the ratio (q_xy/q_z)/(σ/T) where (σ/T)² q_z² underflows or overflows.
inline double very_rough_argument(double qxy2, double qz2, double sigma_over_T) {
    if (qxy2 == 0.0) return 0.0;
    const double den = sigma_over_T * sigma_over_T * qz2;
    if (den > 0.0 && den <= 1.7976931348623157e308) return qxy2 / den;
    const double t = std::sqrt(qxy2 / qz2) / sigma_over_T;
    return t * t;
}

// Eq. 4 / Eq. 5 as published: prefactor T²/(A σ²) F²/v_z² P(T² v_xy²/(σ² v_z²)).
inline double diffuse_power_very_rough(Correlation c, double F2, double sigma_um, double T_um,
                                       double area_um2, double vz2, double vxy2) {
    const double s2 = sigma_um * sigma_um, T2 = T_um * T_um;
    return info(c).diffuse_prefactor * T2 / (area_um2 * s2) * F2 / vz2 *
           very_rough_profile(c, T2 * vxy2 / (s2 * vz2));
}

// g → ∞ limit of the exact series, prefactor (T²/A) F² h(g) (h = series_term_weight); Eq. 4
// itself where the closed form is that limit (Gaussian).
inline double diffuse_power_very_rough_series_limit(Correlation c, double F2, double sigma_um,
                                                    double T_um, double area_um2, double g,
                                                    double vz2, double vxy2) {
    if (info(c).closed_form_is_series_limit)
        return diffuse_power_very_rough(c, F2, sigma_um, T_um, area_um2, vz2, vxy2);
    return info(c).diffuse_prefactor * T_um * T_um / area_um2 * F2 *
           series_term_weight(c, g, T_um * T_um * vxy2);
}

// Very-rough brightness shapes, which depend on the slope ratio σ/T only (constants dropped):
// F²/q_z² P(t²), t² = q_xy²/((σ/T)² q_z²), q = v/k: Eq. 4 = (πT²/(Aσ²k²)) × shape, Eq. 5 =
// (2πT²/(Aσ²k²)) × shape. Finite for every σ/T > 0 (σ/T → 0 gives 0 off the specular
// direction, the specular value on it; σ/T → ∞ gives F²/q_z²).
inline double very_rough_shape(Correlation c, double F2, const ScatteringDirection& q,
                               double sigma_over_T) {
    return F2 / q.qz2() *
           very_rough_profile(c, very_rough_argument(q.qxy2(), q.qz2(), sigma_over_T));
}

// Its natural logarithm, ln F² − ln q_z² + ln P(t²), finite where the shape underflows (ratios
// of very-rough brightnesses at two geometries are formed from these).
inline double log_very_rough_shape(Correlation c, double F2, const ScatteringDirection& q,
                                   double sigma_over_T) {
    return std::log(F2) - std::log(q.qz2()) +
           log_very_rough_profile(c, very_rough_argument(q.qxy2(), q.qz2(), sigma_over_T));
}

// ---------------------------------------------------------------------------------------------
// Validated, user-facing evaluation.

// Lengths (σ, T, λ, X, Y) accepted by the validated functions, in µm: from below the Planck
// length to beyond the observable universe, so that no product of lengths and wavenumbers in
// Eq. 1–5 overflows or underflows to a meaningless 0/0.
inline constexpr double kMinLengthUm = 1e-30;
inline constexpr double kMaxLengthUm = 1e30;
// Throws InvalidArgument "<name> = <value> um is outside the valid range [1e-30, 1e+30] um"
// unless kMinLengthUm <= value_um <= kMaxLengthUm.
void check_length_um(std::string_view name, double value_um);

struct Surface {
    double sigma_um = 0.0;  // RMS height σ
    double T_um = 0.0;      // correlation length T
    Correlation correlation = Correlation::Gaussian;
};

struct ModelOptions {
    GeometricFactor factor = GeometricFactor::VernoldHarvey;  // the paper's recommendation (§4.2)
    Radiometry radiometry = Radiometry::Radiance;             // Harvey's interpretation (§3.3)
    Regime regime = Regime::Auto;
    double wavelength_um = 0.555;  // the paper's mean wavelength (§5)
    double patch_x_um = 500.0;     // half-sizes X, Y of the 2X × 2Y illuminated patch, A = 4XY
    double patch_y_um = 500.0;
    // Auto uses the one-term (slightly-rough) form only when the omitted terms are below this
    // relative size (estimated from the second term); otherwise the exact series.
    double auto_tolerance = 1e-12;
};

struct ScatteredPower {
    double coherent = 0.0;           // ρ0² e^{−g}
    double diffuse = 0.0;            // D in the regime used
    double total = 0.0;              // P = coherent + diffuse (Eq. 1)
    double brightness = 0.0;         // E/K: total under the chosen radiometric interpretation
    double g = 0.0;                  // σ² v_z² at this geometry
    Regime regime = Regime::Series;  // the regime actually used (never Auto)
    RoughnessClass roughness_class = RoughnessClass::SlightlyRough;
    // How D was evaluated (for regime Series: summation, or the large-g expansion where the sum
    // underflows or loses accuracy) and a bound on its relative error against the exact series
    // (regime Series, or SlightlyRough chosen by Auto: the omitted terms); 0 for a closed form
    // asked for by name, which is evaluated as defined (rounding only).
    DiffuseMethod method = DiffuseMethod::Summation;
    double relative_error_bound = 0.0;
};

// Eq. 1 at one geometry. Validates: θi, θs in [0°, 90°), φs finite, σ, T, λ, X, Y in
// [kMinLengthUm, kMaxLengthUm], auto_tolerance in (0, 1); throws InvalidArgument naming the
// input otherwise. Every result field is finite: where the power itself exceeds the double range
// (grazing geometries with a patch far below the wavelength) it throws InvalidArgument saying so.
ScatteredPower mean_scattered_power(const Geometry& geom, const Surface& surface,
                                    const ModelOptions& options = {});

// Very-rough diffuse brightness from σ/T alone (Eq. 4 or Eq. 5 as published, constants dropped,
// times the radiometric factor): what the paper's §4.2 and §5 use. Validates inputs.
double very_rough_brightness(const Geometry& geom, double sigma_over_T, Correlation correlation,
                             GeometricFactor factor = GeometricFactor::VernoldHarvey,
                             Radiometry radiometry = Radiometry::Radiance);

// The diffuse Kirchhoff integral evaluated by direct numerical quadrature (Gauss–Kronrod on
// intervals split at the peak scale and the half-periods of J0), independent of the series:
//   D = (2π/A) F² e^{−g} ∫₀^∞ [exp(g C(τ)) − 1] J0(v_xy τ) τ dτ
// Used to verify the series. Domain (else InvalidArgument naming the value and the domain):
//   0 <= g <= kQuadratureMaxG (1e4),  0 <= T·v_xy <= kQuadratureMaxTvxy (100),
//   F² >= 0, T > 0, A > 0 finite with (2π/A) F² T² finite.
// Inside it the run time is bounded (≲ 50 ms) and the error is absolute, ≲ 1e−12 × the scale
// (2π/A) F² T² × (1 − e^{−g})/max(g, 1)^p (p = 1 Gaussian, 2 exponential: the integral's size
// at the lobe centre), so relative accuracy is lost only where D is many decades below that
// scale (far tails of the lobe, e.g. T·v_xy = 20 at g < 1). Never negative: results below 0
// (rounding in a tail) are returned as 0.
inline constexpr double kQuadratureMaxG = 1e4;
inline constexpr double kQuadratureMaxTvxy = 100.0;
double diffuse_power_quadrature(Correlation correlation, double F2, double T_um, double area_um2,
                                double g, double vxy2);

// ---------------------------------------------------------------------------------------------
// The two-name forms kept for the photograph, CLI and Python code (python/bind_core.cpp); they
// forward to the functions above.
inline double gaussian_series_sum(double g, double T2_vxy2) {
    return diffuse_series_sum(Correlation::Gaussian, g, T2_vxy2);
}
inline double exponential_series_sum(double g, double T2_vxy2) {
    return diffuse_series_sum(Correlation::Exponential, g, T2_vxy2);
}
inline double diffuse_power_gaussian_series(double F2, double T_um, double area_um2, double g,
                                            double vxy2) {
    return diffuse_power_series(Correlation::Gaussian, F2, T_um, area_um2, g, vxy2);
}
inline double diffuse_power_exponential_series(double F2, double T_um, double area_um2, double g,
                                               double vxy2) {
    return diffuse_power_series(Correlation::Exponential, F2, T_um, area_um2, g, vxy2);
}
inline double diffuse_power_slightly_rough_gaussian(double F2, double T_um, double area_um2,
                                                    double g, double vxy2) {
    return diffuse_power_slightly_rough(Correlation::Gaussian, F2, T_um, area_um2, g, vxy2);
}
inline double diffuse_power_slightly_rough_exponential(double F2, double T_um, double area_um2,
                                                       double g, double vxy2) {
    return diffuse_power_slightly_rough(Correlation::Exponential, F2, T_um, area_um2, g, vxy2);
}
inline double diffuse_power_very_rough_gaussian(double F2, double sigma_um, double T_um,
                                                double area_um2, double vz2, double vxy2) {
    return diffuse_power_very_rough(Correlation::Gaussian, F2, sigma_um, T_um, area_um2, vz2, vxy2);
}
inline double diffuse_power_very_rough_exponential(double F2, double sigma_um, double T_um,
                                                   double area_um2, double vz2, double vxy2) {
    return diffuse_power_very_rough(Correlation::Exponential, F2, sigma_um, T_um, area_um2, vz2,
                                    vxy2);
}
// (2πT²/A) F² g/(g² + T² v_xy²)^{3/2}: σ does not enter (nor v_z, beyond g).
inline double diffuse_power_very_rough_exponential_series_limit(double F2, double T_um,
                                                                double area_um2, double g,
                                                                double vxy2) {
    return info(Correlation::Exponential).diffuse_prefactor * T_um * T_um / area_um2 * F2 *
           series_term_weight(Correlation::Exponential, g, T_um * T_um * vxy2);
}

}  // namespace roughscope
