// Roughness estimation from brightness measurements (paper §4): closed forms, valid ranges,
// the general two-geometry solver, uncertainty propagation and derived quantities.
#include "roughscope/estimation/estimation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/toms748_solve.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"

namespace roughscope {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Short human form for numbers in messages (7 significant digits).
std::string fmt(double x) { return format_message(x, 7); }

std::string deg(double rad) { return fmt(rad_to_deg(rad)) + " deg"; }

std::string factor_name(GeometricFactor f) {
    switch (f) {
        case GeometricFactor::Beckmann:
            return "F_Beck";
        case GeometricFactor::VernoldHarvey:
            return "F_VH";
        case GeometricFactor::Ogilvy:
            return "F_Ogilvy";
        case GeometricFactor::Kirchhoff:
            return "F_Kirchhoff";
    }
    return "F";
}

// "in (a, b)", "> a", or why no range can be given (never prints NaN or inf).
std::string range_text(const RatioRange& r) {
    if (std::isnan(r.lower) || std::isnan(r.upper))
        return "unavailable: the model brightness underflows to 0 at one of the geometries";
    if (r.lower > std::numeric_limits<double>::max())
        return "above the largest double (no representable ratio)";
    if (std::isinf(r.upper)) return "> " + fmt(r.lower);
    return "in (" + fmt(r.lower) + ", " + fmt(r.upper) + ")";
}

void check_ratio(std::string_view name, double ratio) { check::positive(name, ratio); }

void check_two_angles(double theta1_rad, double theta2_rad) {
    check::polar_angle("theta1", theta1_rad);
    check::polar_angle("theta2", theta2_rad);
    if (theta1_rad == theta2_rad)
        throw InvalidArgument("theta1 = theta2 = " + deg(theta1_rad) +
                              ": the two incidence angles must differ (the brightness ratio "
                              "carries no information otherwise)");
}

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

// The very-rough terms shared by Eq. 17 and 19.
struct VeryRoughPair {
    double a1, a2;
    double C;  // F1² v_z2²/(F2² v_z1²): κ = (E1/E2)/C
};

VeryRoughPair very_rough_pair(double theta1_rad, double theta2_rad, GeometricFactor factor) {
    check_two_angles(theta1_rad, theta2_rad);
    const NormalViewTerms t1 = normal_view_terms(theta1_rad, factor);
    const NormalViewTerms t2 = normal_view_terms(theta2_rad, factor);
    return {t1.a, t2.a, t1.F2_over_qz2 / t2.F2_over_qz2};
}

[[noreturn]] void throw_no_solution(const std::string& what, double ratio, double theta1_rad,
                                    double theta2_rad, GeometricFactor factor,
                                    const RatioRange& range, const std::string& extra = "") {
    throw NoSolution("E1/E2 = " + check::format_number(ratio) + " has no solution for " + what +
                     " at theta1 = " + deg(theta1_rad) + ", theta2 = " + deg(theta2_rad) +
                     " with " + factor_name(factor) + ": E1/E2 must be " + range_text(range) +
                     extra);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Valid ranges

// Eq. 16: E1/E2 = C exp{(T²/4σ²)(a2 − a1)}.
RatioRange ratio_range_gaussian(double theta1_rad, double theta2_rad, GeometricFactor factor) {
    const VeryRoughPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    return p.a2 > p.a1 ? RatioRange{p.C, kInf} : RatioRange{0.0, p.C};
}

// Eq. 18: E1/E2 = C {(1 + a2 T²/σ²)/(1 + a1 T²/σ²)}^{3/2}.
RatioRange ratio_range_exponential(double theta1_rad, double theta2_rad, GeometricFactor factor) {
    const VeryRoughPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    if (p.a2 > p.a1) {
        const double upper = p.a1 > 0.0 ? p.C * std::pow(p.a2 / p.a1, 1.5) : kInf;
        return {p.C, upper};
    }
    const double lower = p.a2 > 0.0 ? p.C * std::pow(p.a2 / p.a1, 1.5) : 0.0;
    return {lower, p.C};
}

// ---------------------------------------------------------------------------------------------
// §4.2 closed forms

// Eq. 17: σ/T_G = ½ {[a2 − a1]/ln κ}^{1/2}, κ = (E1/E2)/C.
double sigma_over_T_gaussian_from_ratio(double E1_over_E2, double theta1_rad, double theta2_rad,
                                        GeometricFactor factor) {
    check_ratio("E1/E2", E1_over_E2);
    const VeryRoughPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    const double log_kappa = std::log(E1_over_E2) - std::log(p.C);  // no overflow of E1/E2/C
    const double radicand = (p.a2 - p.a1) / log_kappa;
    const double kappa = std::exp(log_kappa);
    if (!(radicand > 0.0) || !std::isfinite(radicand))
        throw_no_solution(
            "Gaussian correlation (Eq. 17)", E1_over_E2, theta1_rad, theta2_rad, factor,
            ratio_range_gaussian(theta1_rad, theta2_rad, factor),
            " (kappa = " + (std::isfinite(kappa) ? fmt(kappa) : std::string("above 1e308")) +
                (p.a2 > p.a1 ? " must exceed 1)" : " must be below 1)"));
    return 0.5 * std::sqrt(radicand);
}

// Eq. 19: σ/T_E = {[a2 − κ^{2/3} a1]/(κ^{2/3} − 1)}^{1/2}.
double sigma_over_T_exponential_from_ratio(double E1_over_E2, double theta1_rad, double theta2_rad,
                                           GeometricFactor factor) {
    check_ratio("E1/E2", E1_over_E2);
    const VeryRoughPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    const double k13 = std::cbrt(E1_over_E2) / std::cbrt(p.C);  // no overflow of E1/E2/C
    const double k23 = k13 * k13;
    const double radicand = (p.a2 - k23 * p.a1) / (k23 - 1.0);
    if (!(radicand > 0.0) || !std::isfinite(radicand))
        throw_no_solution("exponential correlation (Eq. 19)", E1_over_E2, theta1_rad, theta2_rad,
                          factor, ratio_range_exponential(theta1_rad, theta2_rad, factor),
                          std::isfinite(radicand)
                              ? " (the radicand of Eq. 19 is " + fmt(radicand) + ")"
                              : std::string());
    return std::sqrt(radicand);
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

// Eq. 17: σ/T = ½ (Δa/L)^{1/2}, L = ln κ ⇒ d(σ/T)/d ln(E1/E2) = −(σ/T)/(2L).
double d_sigma_over_T_gaussian_d_log_ratio(double E1_over_E2, double theta1_rad, double theta2_rad,
                                           GeometricFactor factor) {
    const double s = sigma_over_T_gaussian_from_ratio(E1_over_E2, theta1_rad, theta2_rad, factor);
    const VeryRoughPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    return -s / (2.0 * (std::log(E1_over_E2) - std::log(p.C)));
}

// Eq. 19: (σ/T)² = (a2 − K a1)/(K − 1), K = κ^{2/3} ⇒ d(σ/T)/d ln r = (a1 − a2)K/(3(σ/T)(K−1)²).
double d_sigma_over_T_exponential_d_log_ratio(double E1_over_E2, double theta1_rad,
                                              double theta2_rad, GeometricFactor factor) {
    const double s =
        sigma_over_T_exponential_from_ratio(E1_over_E2, theta1_rad, theta2_rad, factor);
    const VeryRoughPair p = very_rough_pair(theta1_rad, theta2_rad, factor);
    const double k13 = std::cbrt(E1_over_E2) / std::cbrt(p.C);
    const double K = k13 * k13;
    return (p.a1 - p.a2) * K / (3.0 * s * (K - 1.0) * (K - 1.0));
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

// ---------------------------------------------------------------------------------------------
// General two-geometry solver

namespace {

void check_options(const TwoGeometryOptions& o) {
    check::positive("bracket lower bound", o.lower);
    check::positive("bracket upper bound", o.upper);
    if (!(o.lower < o.upper))
        throw InvalidArgument("bracket lower bound = " + fmt(o.lower) +
                              " must be below the upper bound = " + fmt(o.upper));
    if (!(o.relative_tolerance > 0.0 && o.relative_tolerance < 1.0))
        throw InvalidArgument("relative_tolerance = " + fmt(o.relative_tolerance) +
                              " is outside (0, 1)");
    if (o.max_iterations < 1)
        throw InvalidArgument("max_iterations = " + std::to_string(o.max_iterations) +
                              " must be >= 1");
    if (!(o.min_observable_fraction >= 0.0 && o.min_observable_fraction < 1.0))
        throw InvalidArgument("min_observable_fraction = " + fmt(o.min_observable_fraction) +
                              " is outside [0, 1)");
}

std::string geometry_text(const Geometry& g) {
    return "(theta_i = " + deg(g.theta_i_rad) + ", theta_s = " + deg(g.theta_s_rad) +
           ", phi_s = " + deg(g.phi_s_rad) + ")";
}

// ln of the very-rough brightness shape (Eq. 4 / Eq. 5 up to constants) × radiometric factor,
// computed in log space (finite where the shape underflows,
// e.g. exp(−q_xy²/(4(σ/T)²q_z²)) at small σ/T far from the specular direction).
double log_very_rough_brightness_shape(const Geometry& geom, double sigma_over_T, Correlation c,
                                       const TwoGeometryOptions& o) {
    const double F2 = geometric_factor_squared(o.factor, geom);
    const ScatteringDirection q = scattering_direction(geom);
    const double log_shape = c == Correlation::Gaussian
                                 ? log_very_rough_shape_gaussian(F2, q, sigma_over_T)
                                 : log_very_rough_shape_exponential(F2, q, sigma_over_T);
    return log_shape + std::log(radiometric_factor(o.radiometry, geom));
}

ModelOptions model_options(const TwoGeometryOptions& o) {
    ModelOptions m;
    m.factor = o.factor;
    m.radiometry = o.radiometry;
    m.regime = o.regime;
    m.wavelength_um = o.wavelength_um;
    return m;
}

// Diffuse brightness (the measured quantity away from the specular spike) in the chosen regime.
double diffuse_brightness(const Geometry& geom, double sigma_um, double T_um, Correlation c,
                          const TwoGeometryOptions& o) {
    const ScatteredPower p =
        mean_scattered_power(geom, Surface{sigma_um, T_um, c}, model_options(o));
    return p.diffuse * radiometric_factor(o.radiometry, geom);
}

struct Bracket {
    double lo, hi;      // the unknown x
    double f_lo, f_hi;  // ln M at the ends
};

// Shrinks [lo, hi] (geometrically) until ln M is finite at both ends: the brightness of one
// geometry underflows for extreme values of the unknown (e.g. exp(−T²v_xy²/4)).
template <class F>
Bracket finite_bracket(F&& log_ratio, double lo, double hi) {
    auto shrink = [&](double bad, double good_side, bool from_low) {
        // Move from `bad` toward `good_side` by doubling (in log space) until finite, then
        // refine the boundary by bisection in log space.
        double b = bad, step = 1.0;
        double x = bad, fx = log_ratio(x);
        while (!std::isfinite(fx)) {
            b = x;
            x = from_low ? std::min(x * std::exp(step), good_side)
                         : std::max(x / std::exp(step), good_side);
            step *= 2.0;
            fx = log_ratio(x);
            if (x == good_side) break;
        }
        if (!std::isfinite(fx)) return std::pair{x, fx};
        for (int i = 0; i < 40 && b != x; ++i) {
            const double m = std::sqrt(b * x);
            const double fm = log_ratio(m);
            if (std::isfinite(fm)) {
                x = m;
                fx = fm;
            } else {
                b = m;
            }
            if (std::abs(std::log(x / b)) < 1e-3) break;
        }
        return std::pair{x, fx};
    };
    auto [l, fl] = shrink(lo, hi, true);
    auto [h, fh] = shrink(hi, l, false);
    return {l, h, fl, fh};
}

struct RootResult {
    double x;
    Bracket bracket;
};

// The root of g (in ln x) inside [ya, yb] where g changes sign, by TOMS 748; returns x.
template <class G>
double polish_root(G&& g, double ya, double yb, double fa, double fb, const TwoGeometryOptions& o) {
    if (fa == 0) return std::exp(ya);
    if (fb == 0) return std::exp(yb);
    const double tol = o.relative_tolerance;
    auto stop = [tol](double a, double c) { return std::abs(c - a) <= tol; };
    std::uintmax_t iterations = static_cast<std::uintmax_t>(o.max_iterations);
    const auto [ra, rb] = boost::math::tools::toms748_solve(g, ya, yb, fa, fb, stop, iterations);
    if (iterations >= static_cast<std::uintmax_t>(o.max_iterations) && std::abs(rb - ra) > tol)
        throw NoSolution("the root finder did not converge in " + std::to_string(o.max_iterations) +
                         " iterations");
    return std::exp(0.5 * (ra + rb));
}

template <class F>
RootResult solve_log_ratio(
    F&& log_ratio, double target, const TwoGeometryOptions& o,
    const std::function<std::string(const RatioRange&, const Bracket&)>& no_solution_message) {
    // Bracket the root by expanding geometrically from the middle of [lower, upper] (in log
    // space) until ln M − target changes sign. Where the model is not finite (the brightness of
    // one geometry underflowed), a side's step is halved toward the last finite point instead:
    // the side stops only at its bound or once the edge of the finite range is located to 1e-9
    // in ln x (a root between the last finite point and that edge is not skipped).
    auto g = [&](double y) { return log_ratio(std::exp(y)) - target; };
    const double ylo = std::log(o.lower), yhi = std::log(o.upper);
    const double ymid = 0.5 * (ylo + yhi);
    struct Side {
        double y, f;
        double bound;                 // ln lower or ln upper
        double dir;                   // −1 toward the lower bound, +1 toward the upper
        std::optional<double> y_bad;  // nearest point found non-finite beyond y
        double step = 2.0;
        bool can_grow() const {
            if (dir * (bound - y) <= 0.0) return false;
            return !y_bad || std::abs(*y_bad - y) > 1e-9;
        }
    };
    Side low{ymid, 0.0, ylo, -1.0, {}}, high{ymid, 0.0, yhi, 1.0, {}};
    low.y = std::max(ylo, ymid - 1.0);
    high.y = std::min(yhi, ymid + 1.0);
    low.f = g(low.y);
    high.f = g(high.y);
    // A start that is not finite: it becomes the side's known bad point, and the side restarts
    // from the middle.
    for (Side* side : {&low, &high}) {
        if (!std::isfinite(side->f)) {
            side->y_bad = side->y;
            side->y = ymid;
            side->f = g(ymid);
        }
    }
    auto grow = [&](Side& side) {
        double y = side.y + side.dir * side.step;
        if (side.dir * (y - side.bound) > 0.0) y = side.bound;
        if (side.y_bad && side.dir * (y - *side.y_bad) >= 0.0) y = 0.5 * (side.y + *side.y_bad);
        const double f = g(y);
        if (std::isfinite(f)) {
            side.y = y;
            side.f = f;
            side.step *= 2.0;
        } else {
            side.y_bad = y;
        }
    };
    auto same_sign = [](double u, double v) { return (u > 0) == (v > 0) && u != 0 && v != 0; };
    while (std::isfinite(low.f) && std::isfinite(high.f) && same_sign(low.f, high.f) &&
           (low.can_grow() || high.can_grow())) {
        if (low.can_grow()) grow(low);
        if (high.can_grow()) grow(high);
    }
    double ya = low.y, yb = high.y, fa = low.f, fb = high.f;
    if (!(std::isfinite(fa) && std::isfinite(fb)) || ((fa > 0) == (fb > 0) && fa != 0 && fb != 0)) {
        // No sign change: the ratio is outside what the model produces. Report the range the
        // model spans over the (finite part of the) bracket.
        const Bracket b = finite_bracket(log_ratio, o.lower, o.upper);
        const RatioRange range{std::exp(std::min(b.f_lo, b.f_hi)),
                               std::exp(std::max(b.f_lo, b.f_hi))};
        throw NoSolution(no_solution_message(range, b));
    }
    return {polish_root(g, ya, yb, fa, fb, o), {}};
}

// Every solution of ln M(x) = target in [lower, upper] for a model ratio that need not be
// monotonic in x (the exact series in T: the two geometries' diffuse powers change regime at
// different T). ln M is sampled on a grid of 4 points per decade of x; the edges of the finite
// part are located by bisection; a sign change between neighbours is a root (TOMS 748); an
// interior extremum of the samples is refined (Brent) and, when it crosses the target, gives two
// roots. The range reported for "no solution" is the one M spans over the samples and extrema.
struct ScanResult {
    std::vector<double> roots;  // increasing
    RatioRange range;
    Bracket bracket;  // the finite part of [lower, upper]
};

template <class F>
ScanResult scan_log_ratio(F&& log_ratio, double target, const TwoGeometryOptions& o) {
    auto g = [&](double y) { return log_ratio(std::exp(y)) - target; };
    const double ylo = std::log(o.lower), yhi = std::log(o.upper);
    constexpr double kPointsPerDecade = 4.0;
    const auto n =
        static_cast<std::size_t>(std::ceil((yhi - ylo) / std::log(10.0) * kPointsPerDecade)) + 1;
    std::vector<double> ys, fs;
    ys.reserve(n + 4);
    fs.reserve(n + 4);
    // Bisection toward the edge of the finite part between a finite and a non-finite sample, to
    // 1e-4 in ln x (a root closer than that to where the brightness underflows is not looked for).
    auto edge = [&](double y_good, double y_bad) {
        for (int i = 0; i < 60 && std::abs(y_bad - y_good) > 1e-4; ++i) {
            const double m = 0.5 * (y_good + y_bad);
            if (std::isfinite(g(m)))
                y_good = m;
            else
                y_bad = m;
        }
        return y_good;
    };
    double y_prev = 0.0, f_prev = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t j = 0; j < n; ++j) {
        const double y =
            j + 1 == n ? yhi
                       : ylo + (yhi - ylo) * static_cast<double>(j) / static_cast<double>(n - 1);
        const double f = g(y);
        if (j > 0 && std::isfinite(f) != std::isfinite(f_prev)) {
            const double ye = std::isfinite(f) ? edge(y, y_prev) : edge(y_prev, y);
            if (ye != y && ye != y_prev) {
                ys.push_back(ye);
                fs.push_back(g(ye));
            }
        }
        // Finite samples, and the first non-finite one after finite ones (it marks a gap in
        // the finite part).
        if (std::isfinite(f) || (!ys.empty() && std::isfinite(fs.back()))) {
            ys.push_back(y);
            fs.push_back(f);
        }
        y_prev = y;
        f_prev = f;
    }
    ScanResult out;
    double f_min = std::numeric_limits<double>::infinity(), f_max = -f_min;
    double y_first = yhi, y_last = ylo;
    for (std::size_t j = 0; j < ys.size(); ++j) {
        if (!std::isfinite(fs[j])) continue;
        f_min = std::min(f_min, fs[j]);
        f_max = std::max(f_max, fs[j]);
        y_first = std::min(y_first, ys[j]);
        y_last = std::max(y_last, ys[j]);
    }
    auto add_root = [&](double ya, double yb, double fa, double fb) {
        out.roots.push_back(fa == 0.0 ? std::exp(ya) : polish_root(g, ya, yb, fa, fb, o));
    };
    const int kBits = 24;
    for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
        const double fa = fs[j], fb = fs[j + 1];
        if (!std::isfinite(fa) || !std::isfinite(fb)) continue;
        if (fa == 0.0 || (fa > 0) != (fb > 0)) {
            add_root(ys[j], ys[j + 1], fa, fb);
            continue;
        }
        // An interior extremum of the samples on [y_j − 1, y_j + 1] without a sign change.
        if (j == 0 || !std::isfinite(fs[j - 1])) continue;
        const double fl = fs[j - 1];
        const bool is_min = fa < fl && fa<fb, is_max = fa> fl && fa > fb;
        if (!is_min && !is_max) continue;
        const double sign = is_min ? 1.0 : -1.0;
        const auto [y_ext, f_ext_signed] = boost::math::tools::brent_find_minima(
            [&](double y) {
                const double f = g(y);
                return std::isfinite(f) ? sign * f : std::numeric_limits<double>::infinity();
            },
            ys[j - 1], ys[j + 1], kBits);
        const double f_ext = sign * f_ext_signed;
        f_min = std::min(f_min, f_ext);
        f_max = std::max(f_max, f_ext);
        if (f_ext != 0.0 && (f_ext > 0) != (fa > 0)) {
            // Two roots around the extremum, between the neighbours (a root between y_{j−1} and
            // y_j was taken above only if the samples changed sign there, which they did not).
            if (y_ext > ys[j - 1] && y_ext < ys[j + 1]) {
                add_root(ys[j - 1], y_ext, fl, f_ext);
                add_root(y_ext, ys[j + 1], f_ext, fb);
            }
        }
    }
    std::sort(out.roots.begin(), out.roots.end());
    // Roots closer than the tolerance are one (a root on a sample is found from both sides).
    out.roots.erase(std::unique(out.roots.begin(), out.roots.end(),
                                [&](double a, double b) {
                                    return std::abs(std::log(b / a)) <= 10.0 * o.relative_tolerance;
                                }),
                    out.roots.end());
    if (std::isfinite(f_min))
        out.range = RatioRange{std::exp(f_min + target), std::exp(f_max + target)};
    out.bracket = Bracket{std::exp(y_first), std::exp(y_last), f_min + target, f_max + target};
    return out;
}

// d ln M / d ln x by central differences (used only for the uncertainty of numeric solutions).
template <class F>
double d_log_ratio_d_log_x(F&& log_ratio, double x) {
    const double h = 1e-4;
    return (log_ratio(x * std::exp(h)) - log_ratio(x * std::exp(-h))) / (2.0 * h);
}

std::string ratio_text(double r) { return "E1/E2 = " + check::format_number(r); }

}  // namespace

double model_ratio_very_rough(const Geometry& geom1, const Geometry& geom2, double sigma_over_T,
                              Correlation correlation, const TwoGeometryOptions& options) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check::positive("sigma/T", sigma_over_T);
    return std::exp(log_very_rough_brightness_shape(geom1, sigma_over_T, correlation, options) -
                    log_very_rough_brightness_shape(geom2, sigma_over_T, correlation, options));
}

double model_ratio_diffuse(const Geometry& geom1, const Geometry& geom2, double sigma_um,
                           double T_um, Correlation correlation,
                           const TwoGeometryOptions& options) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    return diffuse_brightness(geom1, sigma_um, T_um, correlation, options) /
           diffuse_brightness(geom2, sigma_um, T_um, correlation, options);
}

namespace {

// ln M(σ/T) for the very-rough solver.
auto very_rough_log_ratio(const Geometry& g1, const Geometry& g2, Correlation c,
                          const TwoGeometryOptions& o) {
    return [=, &o](double s) {
        return log_very_rough_brightness_shape(g1, s, c, o) -
               log_very_rough_brightness_shape(g2, s, c, o);
    };
}

auto diffuse_log_ratio_T(const Geometry& g1, const Geometry& g2, double sigma_um, Correlation c,
                         const TwoGeometryOptions& o) {
    return [=, &o](double T) {
        return std::log(diffuse_brightness(g1, sigma_um, T, c, o)) -
               std::log(diffuse_brightness(g2, sigma_um, T, c, o));
    };
}

void check_distinct_very_rough(const Geometry& g1, const Geometry& g2) {
    const ScatteringDirection q1 = scattering_direction(g1), q2 = scattering_direction(g2);
    const double a1 = q1.qxy2() / q1.qz2(), a2 = q2.qxy2() / q2.qz2();
    if (std::abs(a1 - a2) <= 1e-12 * std::max({a1, a2, 1e-300}))
        throw InvalidArgument("geom1 " + geometry_text(g1) + " and geom2 " + geometry_text(g2) +
                              " have the same v_xy^2/v_z^2 = " + fmt(a1) +
                              ": their brightness ratio does not depend on sigma/T");
}

void check_distinct_diffuse(const Geometry& g1, const Geometry& g2, double wavelength_um) {
    const double v1 = scattering_vector(g1, wavelength_um).vxy2();
    const double v2 = scattering_vector(g2, wavelength_um).vxy2();
    if (std::abs(v1 - v2) <= 1e-12 * std::max({v1, v2, 1e-300}))
        throw InvalidArgument("geom1 " + geometry_text(g1) + " and geom2 " + geometry_text(g2) +
                              " have the same v_xy^2 = " + fmt(v1) +
                              " um^-2: their brightness ratio does not depend on T");
}

}  // namespace

// Eq. 16/18 generalised to any two geometries, inverted by TOMS 748.
double sigma_over_T_two_geometries(double E1_over_E2, const Geometry& geom1, const Geometry& geom2,
                                   Correlation correlation, const TwoGeometryOptions& options) {
    check_ratio("E1/E2", E1_over_E2);
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check_options(options);
    check_distinct_very_rough(geom1, geom2);
    auto f = very_rough_log_ratio(geom1, geom2, correlation, options);
    return solve_log_ratio(f, std::log(E1_over_E2), options,
                           [&](const RatioRange& r, const Bracket& b) {
                               return ratio_text(E1_over_E2) + " has no solution for sigma/T (" +
                                      std::string(correlation == Correlation::Gaussian
                                                      ? "Gaussian correlation, Eq. 4"
                                                      : "exponential correlation, Eq. 5") +
                                      ", " + factor_name(options.factor) + ") at geom1 " +
                                      geometry_text(geom1) + ", geom2 " + geometry_text(geom2) +
                                      ": for sigma/T in [" + fmt(b.lo) + ", " + fmt(b.hi) +
                                      "] E1/E2 must be " + range_text(r);
                           })
        .x;
}

// Eq. 14 generalised (any geometries, any regime and correlation), inverted by TOMS 748.
double correlation_length_two_geometries(double E1_over_E2, const Geometry& geom1,
                                         const Geometry& geom2, double sigma_um,
                                         Correlation correlation,
                                         const TwoGeometryOptions& options) {
    check_ratio("E1/E2", E1_over_E2);
    check_length_um("sigma", sigma_um);
    check_length_um("wavelength", options.wavelength_um);
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check_options(options);
    check_distinct_diffuse(geom1, geom2, options.wavelength_um);
    auto f = diffuse_log_ratio_T(geom1, geom2, sigma_um, correlation, options);
    const auto context = [&] {
        return " (" + std::string(to_string(correlation)) + " correlation, " +
               std::string(to_string(options.regime)) + " regime, " + factor_name(options.factor) +
               ", sigma = " + fmt(sigma_um) + " um, lambda = " + fmt(options.wavelength_um) +
               " um) at geom1 " + geometry_text(geom1) + ", geom2 " + geometry_text(geom2);
    };
    const auto no_solution = [&](const RatioRange& r, const Bracket& b) {
        return ratio_text(E1_over_E2) + " has no solution for the correlation length" + context() +
               ": for T in [" + fmt(b.lo) + ", " + fmt(b.hi) + "] um E1/E2 must be " +
               range_text(r);
    };
    // The first term (Eq. 3, or the exponential one) and the very-rough forms give ln M linear
    // in T² (Gaussian) or in ln(1 + T²·const) terms of one sign: monotonic in T. The exact series
    // need not be (the geometries' diffuse powers change regime at different T): every solution
    // is looked for, and more than one is an error that lists them.
    if (options.regime != Regime::Series && options.regime != Regime::Auto)
        return solve_log_ratio(f, std::log(E1_over_E2), options, no_solution).x;
    ScanResult scan = scan_log_ratio(f, std::log(E1_over_E2), options);
    if (scan.roots.empty()) throw NoSolution(no_solution(scan.range, scan.bracket));
    const auto observable = [&](double T_um) {
        for (const Geometry* g : {&geom1, &geom2}) {
            const Geometry specular{g->theta_i_rad, g->theta_i_rad, 0.0};
            const double d = diffuse_brightness(*g, sigma_um, T_um, correlation, options);
            const double peak = diffuse_brightness(specular, sigma_um, T_um, correlation, options);
            if (!(peak > 0.0) || !(d >= options.min_observable_fraction * peak)) return false;
        }
        return true;
    };
    // Several solutions: those where a camera could not see the sample are dropped (kept all
    // when that leaves none).
    if (scan.roots.size() > 1) {
        std::vector<double> kept;
        std::copy_if(scan.roots.begin(), scan.roots.end(), std::back_inserter(kept), observable);
        if (!kept.empty()) scan.roots = std::move(kept);
    }
    if (scan.roots.size() > 1) {
        std::string list;
        for (std::size_t k = 0; k < scan.roots.size(); ++k)
            list += (k == 0                       ? ""
                     : k + 1 == scan.roots.size() ? " and "
                                                  : ", ") +
                    fmt(scan.roots[k]);
        throw NoSolution(ratio_text(E1_over_E2) + " does not determine the correlation length" +
                         context() + ": the model ratio is not monotonic in T there, and T = " +
                         list + " um all give it; narrow the bracket [" + fmt(options.lower) +
                         ", " + fmt(options.upper) + "] um to the solution wanted");
    }
    return scan.roots.front();
}

// ---------------------------------------------------------------------------------------------
// Derived quantities and roughness class

namespace {

std::string class_text(RoughnessClass c) { return std::string(to_string(c)); }

constexpr std::size_t kListedMeasurements = 4;

// "measurement 2 (...)" or "measurements 1 (...), 3 (...), ... (7 of 205)".
std::string list_measurements(const std::vector<std::string>& items, std::size_t count,
                              std::size_t total) {
    std::string s = count == 1 ? "measurement " : "measurements ";
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
    if (count > items.size()) s += ", ...";
    if (count > 1) s += " (" + std::to_string(count) + " of " + std::to_string(total) + ")";
    return s;
}

bool is_normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

void check_noise(const BrightnessNoise& n) {
    check::non_negative("relative noise of E1", n.relative_E1);
    check::non_negative("relative noise of E2", n.relative_E2);
}

double log_ratio_variance(const BrightnessNoise& n) {
    return n.relative_E1 * n.relative_E1 + n.relative_E2 * n.relative_E2;
}

}  // namespace

// §3.5: m = σ√2/T, θK = π/2 − atan(m), ξK = 1 − exp(−T²/4σ²), with first-order errors.
void fill_derived_quantities(RoughnessEstimate& est, const std::vector<Geometry>& geometries) {
    if (!est.sigma_over_T) return;
    const double s = est.sigma_over_T->value, sd = est.sigma_over_T->std_error;
    est.rms_slope = Estimate{rms_slope(s), std::sqrt(2.0) * sd};
    est.theta_K_rad = Estimate{caron_theta_K_rad(s), std::sqrt(2.0) / (1.0 + 2.0 * s * s) * sd};
    est.xi_K = Estimate{caron_xi_K(s), std::exp(-1.0 / (4.0 * s * s)) / (2.0 * s * s * s) * sd};
    if (est.correlation == Correlation::Exponential)
        est.warnings.push_back(
            "theta_K, xi_K and the RMS slope are Caron's formulas for a Gaussian correlation "
            "function; for this exponential-correlation estimate they are indicative only");
    // θK is Caron's angle for a Gaussian correlation: the validity warning uses it only then.
    if (est.correlation != Correlation::Gaussian) return;
    const double theta_K = est.theta_K_rad->value;
    std::vector<std::string> items;
    std::size_t count = 0;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
        const Geometry& g = geometries[i];
        const double angle = std::max(g.theta_i_rad, g.theta_s_rad);
        if (angle > theta_K) {
            ++count;
            if (items.size() < kListedMeasurements)
                items.push_back(std::to_string(i + 1) + " (" +
                                (g.theta_i_rad >= g.theta_s_rad ? "theta_i" : "theta_s") + " = " +
                                deg(angle) + ")");
        }
    }
    if (count > 0)
        est.warnings.push_back(
            list_measurements(items, count, geometries.size()) +
            (count == 1 ? " exceeds" : " exceed") +
            " Caron's angle of RMS slope theta_K = " + deg(theta_K) +
            ": the model is not valid there (paper 5.2: shadowing and multiple scattering)");
}

void fill_roughness_class(RoughnessEstimate& est, const std::vector<Geometry>& geometries,
                          double sigma_um, double wavelength_um,
                          std::optional<RoughnessClass> assumed) {
    est.g.clear();
    double g_max = 0.0;
    std::vector<std::string> items;
    std::size_t count = 0;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
        const double g = roughness_g(geometries[i], sigma_um, wavelength_um);
        est.g.push_back(g);
        g_max = std::max(g_max, g);
        const RoughnessClass c = roughness_class(g);
        if (assumed && c != *assumed) {
            ++count;
            if (items.size() < kListedMeasurements)
                items.push_back(std::to_string(i + 1) + " (g = " + format_message(g, 4) + ", " +
                                class_text(c) + ")");
        }
    }
    if (count > 0) {
        const std::string form =
            *assumed == RoughnessClass::SlightlyRough
                ? "the slightly-rough form (Eq. 3) assumes g < " + fmt(kSlightlyRoughMaxG)
            : *assumed == RoughnessClass::VeryRough
                ? "the very-rough forms (Eq. 4, 5) assume g > " + fmt(kVeryRoughMinG)
                : "the estimator assumes a moderately rough surface";
        est.warnings.push_back(list_measurements(items, count, geometries.size()) + ": " + form +
                               "; the estimate is approximate");
    }
    est.roughness_class = roughness_class(g_max);
    est.roughness_class_assumed = false;
}

// ---------------------------------------------------------------------------------------------
// Estimates with uncertainty

// Eq. 12–13 with first-order propagation of the brightness noise.
RoughnessEstimate estimate_sigma_specular(const SpecularInput& in) {
    check::non_negative("relative noise of E_tot", in.relative_noise_tot);
    check::non_negative("relative noise of E_dif", in.relative_noise_dif);
    double R = in.R_spec;
    if (in.E_tot || in.E_dif) {
        if (!(in.E_tot && in.E_dif))
            throw InvalidArgument(
                "E_tot and E_dif must be given together (R_spec = 1 - E_dif/E_tot)");
        R = specular_reflectance_from_brightness(*in.E_tot, *in.E_dif);
        check::positive("R0", in.R0);
        if (!(R < in.R0))  // name the inputs, not only the derived R_spec
            throw InvalidArgument(
                "R_spec = 1 - E_dif/E_tot = " + check::format_number(R) + " (E_tot = " +
                check::format_number(*in.E_tot) + ", E_dif = " + check::format_number(*in.E_dif) +
                ") is invalid: it must be below R0 = " + check::format_number(in.R0) +
                " (Eq. 13 needs 0 < R_spec < R0; E_dif/E_tot must exceed " +
                check::format_number(1.0 - in.R0) + ")");
    }
    const double sigma = sigma_from_specular(R, in.theta_rad, in.wavelength_um, in.R0);
    const double sd_R = (1.0 - R) * std::sqrt(in.relative_noise_tot * in.relative_noise_tot +
                                              in.relative_noise_dif * in.relative_noise_dif);
    const double dsdR = d_sigma_d_specular_reflectance(R, in.theta_rad, in.wavelength_um, in.R0);
    RoughnessEstimate est;
    const double sd_sigma = sd_R == 0.0 ? 0.0 : std::abs(dsdR) * sd_R;
    est.sigma_um = Estimate{sigma, sd_sigma};
    if (!std::isfinite(sd_sigma))
        est.warnings.push_back(
            "the standard error of sigma is unavailable: at R_spec = " + check::format_number(R) +
            " dsigma/dR_spec times the noise exceeds the double range (R_spec is too close to 0 "
            "for the noise to bound sigma)");
    // Eq. 12 (the coherent term) holds in every regime: no class is assumed.
    const Geometry geom = specular_geometry(in.theta_rad);
    fill_roughness_class(est, {geom}, sigma, in.wavelength_um, std::nullopt);
    return est;
}

// Eq. 14–15 (or the general solver) with first-order propagation.
RoughnessEstimate estimate_correlation_length(const CorrelationLengthInput& in) {
    check_noise(in.noise);
    check::non_negative("standard error of sigma", in.sigma_um_std_error, "um");
    const TwoGeometryOptions& o = in.options;
    const double var_ln_r = log_ratio_variance(in.noise);
    double T = 0.0, dT_dlnr = 0.0, dT_dsigma = 0.0;
    if (is_normal_view(in.geom1) && is_normal_view(in.geom2) &&
        in.correlation == Correlation::Gaussian && o.regime == Regime::SlightlyRough) {
        T = correlation_length_from_ratio(in.E1_over_E2, in.sigma_um, in.geom1.theta_i_rad,
                                          in.geom2.theta_i_rad, o.wavelength_um, o.factor);
        dT_dlnr = d_correlation_length_d_log_ratio(in.E1_over_E2, in.sigma_um, in.geom1.theta_i_rad,
                                                   in.geom2.theta_i_rad, o.wavelength_um, o.factor);
        dT_dsigma = d_correlation_length_d_sigma(in.E1_over_E2, in.sigma_um, in.geom1.theta_i_rad,
                                                 in.geom2.theta_i_rad, o.wavelength_um, o.factor);
    } else {
        T = correlation_length_two_geometries(in.E1_over_E2, in.geom1, in.geom2, in.sigma_um,
                                              in.correlation, o);
        // Implicit function theorem on ln M(σ, T) = ln r.
        auto fT = diffuse_log_ratio_T(in.geom1, in.geom2, in.sigma_um, in.correlation, o);
        const double dlnM_dlnT = d_log_ratio_d_log_x(fT, T);
        auto fs = [&](double sigma) {
            return std::log(diffuse_brightness(in.geom1, sigma, T, in.correlation, o)) -
                   std::log(diffuse_brightness(in.geom2, sigma, T, in.correlation, o));
        };
        const double dlnM_dlns = d_log_ratio_d_log_x(fs, in.sigma_um);
        dT_dlnr = T / dlnM_dlnT;
        dT_dsigma = -(T / in.sigma_um) * dlnM_dlns / dlnM_dlnT;
    }
    const double sd_sigma = in.sigma_um_std_error;
    const double sd_T =
        std::sqrt(dT_dlnr * dT_dlnr * var_ln_r + dT_dsigma * dT_dsigma * sd_sigma * sd_sigma);
    const double s = in.sigma_um / T;
    const double ds_dsigma = 1.0 / T - in.sigma_um / (T * T) * dT_dsigma;
    const double ds_dlnr = -in.sigma_um / (T * T) * dT_dlnr;
    const double sd_s =
        std::sqrt(ds_dsigma * ds_dsigma * sd_sigma * sd_sigma + ds_dlnr * ds_dlnr * var_ln_r);

    RoughnessEstimate est;
    est.correlation = in.correlation;
    est.sigma_um = Estimate{in.sigma_um, sd_sigma};
    est.T_um = Estimate{T, sd_T};
    est.sigma_over_T = Estimate{s, sd_s};
    const std::vector<Geometry> geoms{in.geom1, in.geom2};
    // The one-term forms assume a slightly rough surface; the exact series holds in every
    // regime (Auto picks whichever is accurate), so no class is assumed then.
    fill_roughness_class(est, geoms, in.sigma_um, o.wavelength_um,
                         o.regime == Regime::SlightlyRough
                             ? std::optional<RoughnessClass>(RoughnessClass::SlightlyRough)
                             : std::nullopt);
    fill_derived_quantities(est, geoms);
    return est;
}

// Eq. 16–19 (or the general solver) with first-order propagation.
RoughnessEstimate estimate_slope(const SlopeInput& in) {
    check_noise(in.noise);
    const TwoGeometryOptions& o = in.options;
    double s = 0.0, ds_dlnr = 0.0;
    if (is_normal_view(in.geom1) && is_normal_view(in.geom2)) {
        // θs = 0: the radiometric factor is 1 for both, so Eq. 17/19 apply for any radiometry.
        const double t1 = in.geom1.theta_i_rad, t2 = in.geom2.theta_i_rad;
        if (in.correlation == Correlation::Gaussian) {
            s = sigma_over_T_gaussian_from_ratio(in.E1_over_E2, t1, t2, o.factor);
            ds_dlnr = d_sigma_over_T_gaussian_d_log_ratio(in.E1_over_E2, t1, t2, o.factor);
        } else {
            s = sigma_over_T_exponential_from_ratio(in.E1_over_E2, t1, t2, o.factor);
            ds_dlnr = d_sigma_over_T_exponential_d_log_ratio(in.E1_over_E2, t1, t2, o.factor);
        }
    } else {
        s = sigma_over_T_two_geometries(in.E1_over_E2, in.geom1, in.geom2, in.correlation, o);
        auto f = very_rough_log_ratio(in.geom1, in.geom2, in.correlation, o);
        ds_dlnr = s / d_log_ratio_d_log_x(f, s);
    }
    RoughnessEstimate est;
    est.correlation = in.correlation;
    const double sd_s = std::abs(ds_dlnr) * std::sqrt(log_ratio_variance(in.noise));
    est.sigma_over_T = Estimate{s, sd_s};
    const std::vector<Geometry> geoms{in.geom1, in.geom2};
    if (in.sigma_um) {
        check_length_um("sigma", *in.sigma_um);
        check_length_um("wavelength", o.wavelength_um);
        est.sigma_um = Estimate{*in.sigma_um, 0.0};
        est.T_um = Estimate{*in.sigma_um / s, *in.sigma_um / (s * s) * sd_s};
        fill_roughness_class(est, geoms, *in.sigma_um, o.wavelength_um, RoughnessClass::VeryRough);
    } else {
        est.roughness_class = RoughnessClass::VeryRough;
        est.roughness_class_assumed = true;
    }
    fill_derived_quantities(est, geoms);
    return est;
}

}  // namespace roughscope
