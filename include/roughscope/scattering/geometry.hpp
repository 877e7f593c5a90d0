// Imaging geometry of the paper, §2 (Fig. 1 and Fig. 2).
//
// Convention (used by every function in the library; see docs/conventions.md):
//  * Angles are in radians. θi is the polar angle of the light direction L, θs that of the viewing
//    direction V, both measured from the mean surface normal N, both in [0, π/2).
//  * The local frame (X0, Y0, Z0 = N) is turned so that the projection of L onto the tangent
//    plane points along −X0: the light azimuth is φi = π for every geometry (§2).
//  * φs is the azimuth of V measured from +X0: φs = 0 is the specular half-plane (V mirrors L),
//    φs = π is retro-reflection (V = L).
//  * L and V point away from the surface (computer-vision convention, §2).
#pragma once

#include <numbers>
#include <optional>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace roughscope {

inline constexpr double kPi = std::numbers::pi;

constexpr double deg_to_rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / kPi); }

// One scattering geometry in the paper's frame (φi = π implied).
struct Geometry {
    double theta_i_rad = 0.0;  // incidence polar angle θi
    double theta_s_rad = 0.0;  // scattering (viewing) polar angle θs
    double phi_s_rad = 0.0;    // scattering azimuth φs (0: specular plane, π: retro)
};

// Validated constructor: θi, θs in [0, π/2), φs finite (wrapped to [0, 2π)).
// Throws InvalidArgument naming the bad angle otherwise.
Geometry make_geometry(double theta_i_rad, double theta_s_rad, double phi_s_rad);

namespace check {
// The one validation of a Geometry at an API boundary (§2): θi, θs in [0, π/2), φs finite.
// Throws InvalidArgument naming the angle ("theta_i", or "<which> theta_i" when `which` is given,
// e.g. "geom1 theta_i") and the valid range otherwise.
void geometry(const Geometry& geom, std::string_view which = {});
}  // namespace check

// §2: θi = acos(N·L), θs = acos(N·V), φs = π − acos(L̂p·V̂p) with the tangent-plane projections
// Lp = (N×L)×N and Vp = (N×V)×N. φs is returned in [0, π] (isotropic surfaces cannot tell ±φs).
// When L or V is along N its projection vanishes and φs is set to 0 (the paper's normal-view
// case θs = 0, φs = 0). N, L, V must be finite unit vectors (|‖x‖ − 1| ≤ unit_tolerance), else
// InvalidArgument. Returns std::nullopt when L or V is at or below the horizon (N·L ≤ 1e−12 or
// N·V ≤ 1e−12): a physical zero of brightness, not an error.
std::optional<Geometry> geometry_from_vectors(const Eigen::Vector3d& N, const Eigen::Vector3d& L,
                                              const Eigen::Vector3d& V,
                                              double unit_tolerance = 1e-6);

// From a frame that gives both azimuths (e.g. CUReT's θv, φv, θi, φi; v = viewing direction):
// θs = θv, φs = φv − φi + π (mod 2π). Polar angles validated as in make_geometry.
Geometry geometry_from_two_azimuths(double theta_i_rad, double phi_i_rad, double theta_v_rad,
                                    double phi_v_rad);

// Special cases of §2.
Geometry retro_geometry(double theta_rad);          // L = V: θi = θs = θ, φs = π
Geometry specular_geometry(double theta_rad);       // θi = θs = θ, φs = 0
Geometry normal_view_geometry(double theta_i_rad);  // θs = 0, φs = 0 (Fig. 5b)

// Unit vectors of L and V in the local frame (X0, Y0, N): L = (−sin θi, 0, cos θi),
// V = (sin θs cos φs, sin θs sin φs, cos θs).
Eigen::Vector3d light_direction(const Geometry& geom);
Eigen::Vector3d view_direction(const Geometry& geom);

}  // namespace roughscope
