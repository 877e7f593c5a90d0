#include "roughscope/scattering/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "roughscope/core/errors.hpp"

namespace roughscope {
namespace {

constexpr double kHorizonCos = 1e-12;

double wrap_two_pi(double phi) {
    double w = std::fmod(phi, 2.0 * kPi);
    if (w < 0.0) w += 2.0 * kPi;
    return w;
}

void check_unit(std::string_view name, const Eigen::Vector3d& v, double tol) {
    if (!v.allFinite()) throw InvalidArgument(std::string(name) + " has a non-finite component");
    const double norm = v.norm();
    if (std::abs(norm - 1.0) > tol)
        throw InvalidArgument(
            std::string(name) + " has length " + check::format_number(norm) +
            "; it must be a unit vector (|length - 1| <= " + check::format_number(tol) + ")");
}

}  // namespace

void check::geometry(const Geometry& geom, std::string_view which) {
    const std::string prefix = which.empty() ? std::string() : std::string(which) + " ";
    check::polar_angle(prefix + "theta_i", geom.theta_i_rad);
    check::polar_angle(prefix + "theta_s", geom.theta_s_rad);
    check::azimuth(prefix + "phi_s", geom.phi_s_rad);
}

Geometry make_geometry(double theta_i_rad, double theta_s_rad, double phi_s_rad) {
    check::geometry({theta_i_rad, theta_s_rad, phi_s_rad});
    return {theta_i_rad, theta_s_rad, wrap_two_pi(phi_s_rad)};
}

std::optional<Geometry> geometry_from_vectors(const Eigen::Vector3d& N, const Eigen::Vector3d& L,
                                              const Eigen::Vector3d& V, double unit_tolerance) {
    if (!(std::isfinite(unit_tolerance) && unit_tolerance > 0.0 && unit_tolerance < 1.0))
        throw InvalidArgument("unit_tolerance = " + check::format_number(unit_tolerance) +
                              " is outside the valid range (0, 1)");
    check_unit("N (surface normal)", N, unit_tolerance);
    check_unit("L (light direction)", L, unit_tolerance);
    check_unit("V (viewing direction)", V, unit_tolerance);
    const Eigen::Vector3d n = N.normalized(), l = L.normalized(), v = V.normalized();
    const double cos_i = n.dot(l), cos_s = n.dot(v);
    // At or below the horizon (cosines within rounding of 0 count as grazing).
    if (cos_i <= kHorizonCos || cos_s <= kHorizonCos) return std::nullopt;
    // §2: tangent-plane projections Lp = (N×L)×N, Vp = (N×V)×N.
    const Eigen::Vector3d lp = n.cross(l).cross(n), vp = n.cross(v).cross(n);
    const double lpn = lp.norm(), vpn = vp.norm();
    double phi_s = 0.0;  // normal incidence or normal view: the paper's φs = 0
    if (lpn > 1e-12 && vpn > 1e-12) {
        const double c = std::clamp(lp.dot(vp) / (lpn * vpn), -1.0, 1.0);
        phi_s = kPi - std::acos(c);
    }
    // acos loses precision near 0; atan2 of the tangential and normal parts does not.
    const double theta_i = std::atan2(lpn, cos_i), theta_s = std::atan2(vpn, cos_s);
    return Geometry{theta_i, theta_s, phi_s};
}

Geometry geometry_from_two_azimuths(double theta_i_rad, double phi_i_rad, double theta_v_rad,
                                    double phi_v_rad) {
    check::polar_angle("theta_i", theta_i_rad);
    check::polar_angle("theta_v", theta_v_rad);
    check::azimuth("phi_i", phi_i_rad);
    check::azimuth("phi_v", phi_v_rad);
    return {theta_i_rad, theta_v_rad, wrap_two_pi(phi_v_rad - phi_i_rad + kPi)};
}

Geometry retro_geometry(double theta_rad) { return make_geometry(theta_rad, theta_rad, kPi); }

Geometry specular_geometry(double theta_rad) { return make_geometry(theta_rad, theta_rad, 0.0); }

Geometry normal_view_geometry(double theta_i_rad) { return make_geometry(theta_i_rad, 0.0, 0.0); }

Eigen::Vector3d light_direction(const Geometry& geom) {
    return {-std::sin(geom.theta_i_rad), 0.0, std::cos(geom.theta_i_rad)};
}

Eigen::Vector3d view_direction(const Geometry& geom) {
    const double ss = std::sin(geom.theta_s_rad);
    return {ss * std::cos(geom.phi_s_rad), ss * std::sin(geom.phi_s_rad),
            std::cos(geom.theta_s_rad)};
}

}  // namespace roughscope
