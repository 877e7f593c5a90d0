// Helpers shared by the estimation sources (closed_forms.cpp, two_geometries.cpp,
// estimates.cpp): message formatting, argument checks and the log-ratio functions of the
// two-geometry solver. Internal: not installed.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/estimation/estimation.hpp"

namespace roughscope::estimation_detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// Short human form for numbers in messages (7 significant digits).
inline std::string fmt(double x) { return format_message(x, 7); }

inline std::string deg(double rad) { return fmt(rad_to_deg(rad)) + " deg"; }

inline std::string factor_name(GeometricFactor f) {
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
inline std::string range_text(const RatioRange& r) {
    if (std::isnan(r.lower) || std::isnan(r.upper))
        return "unavailable: the model brightness underflows to 0 at one of the geometries";
    if (r.lower > std::numeric_limits<double>::max())
        return "above the largest double (no representable ratio)";
    if (std::isinf(r.upper)) return "> " + fmt(r.lower);
    return "in (" + fmt(r.lower) + ", " + fmt(r.upper) + ")";
}

inline void check_ratio(std::string_view name, double ratio) { check::positive(name, ratio); }

void check_two_angles(double theta1_rad, double theta2_rad);

[[noreturn]] void throw_no_solution(const std::string& what, double ratio, double theta1_rad,
                                    double theta2_rad, GeometricFactor factor,
                                    const RatioRange& range, const std::string& extra = "");

inline std::string geometry_text(const Geometry& g) {
    return "(theta_i = " + deg(g.theta_i_rad) + ", theta_s = " + deg(g.theta_s_rad) +
           ", phi_s = " + deg(g.phi_s_rad) + ")";
}

inline std::string ratio_text(double r) { return "E1/E2 = " + check::format_number(r); }

// ln of the very-rough brightness shape (Eq. 4 / Eq. 5 up to constants) × radiometric factor,
// computed in log space (finite where the shape underflows, e.g. exp(−q_xy²/(4(σ/T)²q_z²)) at
// small σ/T far from the specular direction).
double log_very_rough_brightness_shape(const Geometry& geom, double sigma_over_T, Correlation c,
                                       const TwoGeometryOptions& o);

// Diffuse brightness (the measured quantity away from the specular spike) in the chosen regime.
double diffuse_brightness(const Geometry& geom, double sigma_um, double T_um, Correlation c,
                          const TwoGeometryOptions& o);

// ln M(σ/T) for the very-rough solver.
inline auto very_rough_log_ratio(const Geometry& g1, const Geometry& g2, Correlation c,
                                 const TwoGeometryOptions& o) {
    return [=, &o](double s) {
        return log_very_rough_brightness_shape(g1, s, c, o) -
               log_very_rough_brightness_shape(g2, s, c, o);
    };
}

// ln M(T) with σ known for the correlation-length solver.
inline auto diffuse_log_ratio_T(const Geometry& g1, const Geometry& g2, double sigma_um,
                                Correlation c, const TwoGeometryOptions& o) {
    return [=, &o](double T) {
        return std::log(diffuse_brightness(g1, sigma_um, T, c, o)) -
               std::log(diffuse_brightness(g2, sigma_um, T, c, o));
    };
}

// d ln M / d ln x by central differences (used only for the uncertainty of numeric solutions).
template <class F>
double d_log_ratio_d_log_x(F&& log_ratio, double x) {
    const double h = 1e-4;
    return (log_ratio(x * std::exp(h)) - log_ratio(x * std::exp(-h))) / (2.0 * h);
}

}  // namespace roughscope::estimation_detail
