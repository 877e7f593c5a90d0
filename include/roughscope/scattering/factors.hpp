// Scattering vector, roughness parameter g, geometric factors F and the radiometric
// interpretation of Beckmann's mean scattered power (paper §3.1–3.3).
//
// Small pure inline functions in the paper's frame (see geometry.hpp). Lengths in micrometres,
// wavenumbers in 1/µm. Inputs are assumed already validated (Geometry from make_geometry and
// friends); the higher-level functions in beckmann.hpp validate at the API boundary.
#pragma once

#include <cmath>
#include <string_view>

#include "roughscope/scattering/geometry.hpp"

namespace roughscope {

// k = 2π/λ in 1/µm (§3.1).
inline double wavenumber_per_um(double wavelength_um) { return 2.0 * kPi / wavelength_um; }

// The scattering vector divided by k (dimensionless), §3.1:
// vx/k = sin θi − sin θs cos φs, vy/k = −sin θs sin φs, vz/k = −(cos θi + cos θs).
struct ScatteringDirection {
    double qx = 0.0;
    double qy = 0.0;
    double qz = 0.0;
    double qxy2() const { return qx * qx + qy * qy; }  // v_xy²/k²
    double qz2() const { return qz * qz; }             // v_z²/k²
};

inline ScatteringDirection scattering_direction(const Geometry& geom) {
    const double si = std::sin(geom.theta_i_rad), ci = std::cos(geom.theta_i_rad);
    const double ss = std::sin(geom.theta_s_rad), cs = std::cos(geom.theta_s_rad);
    return {si - ss * std::cos(geom.phi_s_rad), -ss * std::sin(geom.phi_s_rad), -(ci + cs)};
}

// The scattering vector v = (vx, vy, vz) in 1/µm (§3.1).
struct ScatteringVector {
    double vx = 0.0;
    double vy = 0.0;
    double vz = 0.0;
    double vxy2() const { return vx * vx + vy * vy; }  // v_xy² = vx² + vy²
};

inline ScatteringVector scattering_vector(const Geometry& geom, double wavelength_um) {
    const double k = wavenumber_per_um(wavelength_um);
    const ScatteringDirection q = scattering_direction(geom);
    return {k * q.qx, k * q.qy, k * q.qz};
}

// g = σ² v_z² (§3.1): the roughness parameter that selects the regime.
inline double roughness_g(double sigma_um, double vz_per_um) {
    return sigma_um * sigma_um * vz_per_um * vz_per_um;
}
inline double roughness_g(const Geometry& geom, double sigma_um, double wavelength_um) {
    return roughness_g(sigma_um, scattering_vector(geom, wavelength_um).vz);
}

// Eq. 6: Beckmann's geometric factor
// F_Beck = (1 + cos θi cos θs − sin θi sin θs cos φs) / (cos θi (cos θi + cos θs)).
inline double geometric_factor_beckmann(const Geometry& geom) {
    const double si = std::sin(geom.theta_i_rad), ci = std::cos(geom.theta_i_rad);
    const double ss = std::sin(geom.theta_s_rad), cs = std::cos(geom.theta_s_rad);
    return (1.0 + ci * cs - si * ss * std::cos(geom.phi_s_rad)) / (ci * (ci + cs));
}

// §3.2: the geometric factor F that multiplies the diffuse term, selectable everywhere.
enum class GeometricFactor {
    Beckmann,       // F_Beck, Eq. 6 (original B–K theory)
    VernoldHarvey,  // F_VH² = cos θi (Vernold & Harvey's Lambertian form)
    Ogilvy,         // F_Ogil = F_Beck cos θi
    Kirchhoff,      // F_Kirch = F_Beck cos θi / cos θs (Nieto-Vesperinas & Garcia)
};

// F² for the chosen factor (§3.2). Kirchhoff's factor diverges as θs → π/2; θs < π/2 keeps it
// finite.
inline double geometric_factor_squared(GeometricFactor factor, const Geometry& geom) {
    switch (factor) {
        case GeometricFactor::VernoldHarvey:
            return std::cos(geom.theta_i_rad);
        case GeometricFactor::Beckmann: {
            const double f = geometric_factor_beckmann(geom);
            return f * f;
        }
        case GeometricFactor::Ogilvy: {
            const double f = geometric_factor_beckmann(geom) * std::cos(geom.theta_i_rad);
            return f * f;
        }
        case GeometricFactor::Kirchhoff: {
            const double f = geometric_factor_beckmann(geom) * std::cos(geom.theta_i_rad) /
                             std::cos(geom.theta_s_rad);
            return f * f;
        }
    }
    return 0.0;  // unreachable
}

// §3.3: what Beckmann's P is taken to be.
enum class Radiometry {
    Radiance,   // Harvey et al.: P ∝ scattered radiance, pixel brightness E = K P (default)
    Intensity,  // Ogilvy: P ∝ scattered intensity, so brightness E = K P / cos θs
};

// Multiplier turning P into pixel brightness (up to the gain K) under each interpretation.
inline double radiometric_factor(Radiometry radiometry, const Geometry& geom) {
    return radiometry == Radiometry::Intensity ? 1.0 / std::cos(geom.theta_s_rad) : 1.0;
}

// Names used by the front ends ("beckmann", "vh", "ogilvy", "kirchhoff"; "radiance",
// "intensity"). parse_* throw InvalidArgument listing the accepted names.
std::string_view to_string(GeometricFactor factor);
std::string_view to_string(Radiometry radiometry);
GeometricFactor parse_geometric_factor(std::string_view name);
Radiometry parse_radiometry(std::string_view name);

}  // namespace roughscope
