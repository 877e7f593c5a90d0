// Roughness estimation from brightness measurements (paper §4): the closed forms of §4.1–4.2
// (Eq. 13, 15, 17, 19), their valid ranges and the analytic derivatives of the propagation.
#include <cmath>
#include <string>

#include "estimation_detail.hpp"
#include "roughscope/estimation/estimation.hpp"

namespace roughscope {
namespace estimation_detail {

void check_two_angles(double theta1_rad, double theta2_rad) {
    check::polar_angle("theta1", theta1_rad);
    check::polar_angle("theta2", theta2_rad);
    if (theta1_rad == theta2_rad)
        throw InvalidArgument("theta1 = theta2 = " + deg(theta1_rad) +
                              ": the two incidence angles must differ (the brightness ratio "
                              "carries no information otherwise)");
}

namespace {

// Per-geometry terms of Eq. 16–19 with the viewer on the normal (θs = φs = 0):
// a = v_xy²/v_z² and w = F²/v_z² (both with v/k, the wavenumber cancels in every ratio).
struct NormalViewTerms {
    double a = 0.0;
    double F2_over_qz2 = 0.0;
};

NormalViewTerms normal_view_terms(double theta_rad, GeometricFactor factor) {
    const Geometry geom = normal_view_geometry(theta_rad);
    const ScatteringDirection q = scattering_direction(geom);
    return {q.qxy2() / q.qz2(), geometric_factor_squared(factor, geom) / q.qz2()};
}

// The very-rough terms shared by Eq. 16–19 (correlation.hpp).
NormalViewPair very_rough_pair(double theta1_rad, double theta2_rad, GeometricFactor factor) {
    check_two_angles(theta1_rad, theta2_rad);
    const NormalViewTerms t1 = normal_view_terms(theta1_rad, factor);
    const NormalViewTerms t2 = normal_view_terms(theta2_rad, factor);
    return {t1.a, t2.a, t1.F2_over_qz2 / t2.F2_over_qz2};
}

}  // namespace

[[noreturn]] void throw_no_solution(const std::string& what, double ratio, double theta1_rad,
                                    double theta2_rad, GeometricFactor factor,
                                    const RatioRange& range, const std::string& extra) {
    throw NoSolution("E1/E2 = " + check::format_number(ratio) + " has no solution for " + what +
                     " at theta1 = " + deg(theta1_rad) + ", theta2 = " + deg(theta2_rad) +
                     " with " + factor_name(factor) + ": E1/E2 must be " + range_text(range) +
                     extra);
}

}  // namespace estimation_detail

using namespace estimation_detail;

// ---------------------------------------------------------------------------------------------
// Valid ranges

// Eq. 16 / 18: the ratios E1/E2 = C P(a1/(σ/T)²)/P(a2/(σ/T)²) takes for σ/T in (0, ∞).
RatioRange ratio_range(Correlation correlation, double theta1_rad, double theta2_rad,
                       GeometricFactor factor) {
    return normal_view_ratio_range(correlation, very_rough_pair(theta1_rad, theta2_rad, factor));
}

// ---------------------------------------------------------------------------------------------
// §4.2 closed forms

// Eq. 17: σ/T_G = ½ {[a2 − a1]/ln κ}^{1/2}, κ = (E1/E2)/C;
// Eq. 19: σ/T_E = {[a2 − κ^{2/3} a1]/(κ^{2/3} − 1)}^{1/2}.
double sigma_over_T_from_ratio(Correlation correlation, double E1_over_E2, double theta1_rad,
                               double theta2_rad, GeometricFactor factor) {
    check_ratio("E1/E2", E1_over_E2);
    const NormalViewPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    const double s = sigma_over_T_from_normal_view_ratio(correlation, p, E1_over_E2);
    if (std::isnan(s)) {
        const CorrelationInfo& c = info(correlation);
        throw_no_solution(
            std::string(c.adjective) + " correlation (" + std::string(c.inverse_equation) + ")",
            E1_over_E2, theta1_rad, theta2_rad, factor, normal_view_ratio_range(correlation, p),
            ratio_inverse_no_solution_detail(correlation, p, E1_over_E2));
    }
    return s;
}

// ---------------------------------------------------------------------------------------------
// §4.1 closed forms

// §4.1.1: R_spec = 1 − Ẽ_dif/Ẽ_tot.
double specular_reflectance_from_brightness(double E_tot, double E_dif) {
    check::positive("E_tot", E_tot);
    check::positive("E_dif", E_dif);
    if (!(E_dif < E_tot))
        throw InvalidArgument("E_dif = " + check::format_number(E_dif) +
                              " must be below E_tot = " + check::format_number(E_tot) +
                              " (the diffuse brightness beside the highlight cannot exceed the "
                              "peak brightness)");
    return 1.0 - E_dif / E_tot;
}

// Eq. 13: σ = (λ/(4π cos θ)) [ln(R0/R_spec)]^{1/2}.
double sigma_from_specular(double R_spec, double theta_rad, double wavelength_um, double R0) {
    check::positive("R_spec", R_spec);
    check::positive("R0", R0);
    check::polar_angle("theta", theta_rad);
    check_length_um("wavelength", wavelength_um);
    if (!(R_spec < R0))
        throw InvalidArgument("R_spec = " + check::format_number(R_spec) +
                              " is invalid: it must be below R0 = " + check::format_number(R0) +
                              " (Eq. 13 needs 0 < R_spec < R0)");
    // ln(R0/R_spec) as a difference: R0/R_spec overflows for a subnormal R_spec.
    return wavelength_um / (4.0 * kPi * std::cos(theta_rad)) *
           std::sqrt(std::log(R0) - std::log(R_spec));
}

namespace {

// Eq. 14 terms at normal view: g, F², v_xy² for one incidence angle.
struct SlightlyRoughTerms {
    double g, F2, vxy2, vz2;
};

SlightlyRoughTerms slightly_rough_terms(double theta_rad, double sigma_um, double wavelength_um,
                                        GeometricFactor factor) {
    const Geometry geom = normal_view_geometry(theta_rad);
    const ScatteringVector v = scattering_vector(geom, wavelength_um);
    return {roughness_g(sigma_um, v.vz), geometric_factor_squared(factor, geom), v.vxy2(),
            v.vz * v.vz};
}

struct Eq15 {
    SlightlyRoughTerms t1, t2;
    double ln_ratio_at_T0;  // ln of Eq. 14 at T = 0
};

Eq15 eq15_terms(double sigma_um, double theta1_rad, double theta2_rad, double wavelength_um,
                GeometricFactor factor) {
    check_length_um("sigma", sigma_um);
    check_length_um("wavelength", wavelength_um);
    check_two_angles(theta1_rad, theta2_rad);
    const auto t1 = slightly_rough_terms(theta1_rad, sigma_um, wavelength_um, factor);
    const auto t2 = slightly_rough_terms(theta2_rad, sigma_um, wavelength_um, factor);
    const double ln0 = std::log(t1.g * t1.F2 / (t2.g * t2.F2)) + t2.g - t1.g;
    return {t1, t2, ln0};
}

}  // namespace

RatioRange ratio_range_correlation_length(double sigma_um, double theta1_rad, double theta2_rad,
                                          double wavelength_um, GeometricFactor factor) {
    const Eq15 e = eq15_terms(sigma_um, theta1_rad, theta2_rad, wavelength_um, factor);
    const double r0 = std::exp(e.ln_ratio_at_T0);
    return e.t2.vxy2 > e.t1.vxy2 ? RatioRange{r0, kInf} : RatioRange{0.0, r0};
}

// Eq. 15: T = 2 [(g1 − g2 + ln ζ)/(v_xy2² − v_xy1²)]^{1/2}, ζ = g2F2²E1/(g1F1²E2).
double correlation_length_from_ratio(double E1_over_E2, double sigma_um, double theta1_rad,
                                     double theta2_rad, double wavelength_um,
                                     GeometricFactor factor) {
    check_ratio("E1/E2", E1_over_E2);
    const Eq15 e = eq15_terms(sigma_um, theta1_rad, theta2_rad, wavelength_um, factor);
    const double ln_zeta = std::log(E1_over_E2 * e.t2.g * e.t2.F2 / (e.t1.g * e.t1.F2));
    const double radicand = (e.t1.g - e.t2.g + ln_zeta) / (e.t2.vxy2 - e.t1.vxy2);
    if (!(radicand > 0.0) || !std::isfinite(radicand))
        throw_no_solution(
            "the correlation length (Eq. 15, sigma = " + fmt(sigma_um) +
                " um, lambda = " + fmt(wavelength_um) + " um)",
            E1_over_E2, theta1_rad, theta2_rad, factor,
            ratio_range_correlation_length(sigma_um, theta1_rad, theta2_rad, wavelength_um, factor),
            std::isfinite(radicand) ? " (the radicand of Eq. 15 is " + fmt(radicand) + ")" : "");
    return 2.0 * std::sqrt(radicand);
}

// ---------------------------------------------------------------------------------------------
// Analytic derivatives for the propagation of brightness noise

// Eq. 17: σ/T = ½ (Δa/L)^{1/2}, L = ln κ ⇒ d(σ/T)/d ln(E1/E2) = −(σ/T)/(2L);
// Eq. 19: (σ/T)² = (a2 − K a1)/(K − 1), K = κ^{2/3} ⇒ d(σ/T)/d ln r = (a1 − a2)K/(3(σ/T)(K−1)²).
double d_sigma_over_T_d_log_ratio(Correlation correlation, double E1_over_E2, double theta1_rad,
                                  double theta2_rad, GeometricFactor factor) {
    const double s =
        sigma_over_T_from_ratio(correlation, E1_over_E2, theta1_rad, theta2_rad, factor);
    const NormalViewPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    return d_sigma_over_T_d_log_ratio(correlation, p, E1_over_E2, s);
}

namespace {

// Eq. 15 at the solution: T, its terms and the numerator N = (T²/4)(v_xy2² − v_xy1²).
struct Eq15Solution {
    double T;
    Eq15 e;
    double N;
};

Eq15Solution eq15_solution(double E1_over_E2, double sigma_um, double theta1_rad, double theta2_rad,
                           double wavelength_um, GeometricFactor factor) {
    const double T = correlation_length_from_ratio(E1_over_E2, sigma_um, theta1_rad, theta2_rad,
                                                   wavelength_um, factor);
    const Eq15 e = eq15_terms(sigma_um, theta1_rad, theta2_rad, wavelength_um, factor);
    return {T, e, T * T / 4.0 * (e.t2.vxy2 - e.t1.vxy2)};
}

}  // namespace

// Eq. 15: T = 2 (N/D)^{1/2}, dN/d ln r = 1 ⇒ dT/d ln r = T/(2N).
double d_correlation_length_d_log_ratio(double E1_over_E2, double sigma_um, double theta1_rad,
                                        double theta2_rad, double wavelength_um,
                                        GeometricFactor factor) {
    const Eq15Solution s =
        eq15_solution(E1_over_E2, sigma_um, theta1_rad, theta2_rad, wavelength_um, factor);
    return s.T / (2.0 * s.N);
}

// Eq. 15: dN/dσ = 2σ(v_z1² − v_z2²) (ζ does not depend on σ) ⇒ dT/dσ = Tσ(v_z1² − v_z2²)/N.
double d_correlation_length_d_sigma(double E1_over_E2, double sigma_um, double theta1_rad,
                                    double theta2_rad, double wavelength_um,
                                    GeometricFactor factor) {
    const Eq15Solution s =
        eq15_solution(E1_over_E2, sigma_um, theta1_rad, theta2_rad, wavelength_um, factor);
    return s.T * sigma_um * (s.e.t1.vz2 - s.e.t2.vz2) / s.N;
}

// Eq. 13: σ = c [ln(R0/R)]^{1/2} ⇒ dσ/dR = −σ/(2 R ln(R0/R)).
double d_sigma_d_specular_reflectance(double R_spec, double theta_rad, double wavelength_um,
                                      double R0) {
    const double sigma = sigma_from_specular(R_spec, theta_rad, wavelength_um, R0);
    return -sigma / (2.0 * R_spec * (std::log(R0) - std::log(R_spec)));
}

}  // namespace roughscope
