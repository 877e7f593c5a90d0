#include "roughscope/scattering/retro.hpp"

#include <cmath>
#include <string>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope {
namespace {

void check_retro(double theta_rad, double sigma_over_T) {
    check::polar_angle("theta", theta_rad);
    check::positive("sigma_over_T", sigma_over_T);
}

// (T/σ)² tan²θ, the argument shared by Eq. 7–10.
double slope_term(double theta_rad, double sigma_over_T) {
    const double t = std::tan(theta_rad) / sigma_over_T;
    return t * t;
}

}  // namespace

// Eq. 7–10
double retro_very_rough(Correlation correlation, GeometricFactor factor, double theta_rad,
                        double sigma_over_T) {
    check_retro(theta_rad, sigma_over_T);
    const double profile = very_rough_profile(correlation, slope_term(theta_rad, sigma_over_T));
    switch (factor) {
        case GeometricFactor::Beckmann:  // Eq. 7, 8
            return profile / std::pow(std::cos(theta_rad), 6);
        case GeometricFactor::VernoldHarvey:  // Eq. 9, 10
            return profile / std::cos(theta_rad);
        case GeometricFactor::Ogilvy:
        case GeometricFactor::Kirchhoff:
            break;
    }
    throw InvalidArgument(std::string("retro_very_rough: the geometric factor ") +
                          std::string(to_string(factor)) +
                          " has no retro-reflection form in the paper (Eq. 7-10: beckmann, vh)");
}

// Eq. 11
double retro_vh_gaussian_slightly_rough(double theta_rad, double sigma_um, double T_um,
                                        double wavelength_um) {
    check::polar_angle("theta", theta_rad);
    check_length_um("sigma", sigma_um);
    check_length_um("T", T_um);
    check_length_um("wavelength", wavelength_um);
    const double k = wavenumber_per_um(wavelength_um);
    const double c = std::cos(theta_rad), s = std::sin(theta_rad);
    const double Ts = T_um * s, sc2 = 2.0 * sigma_um * c;
    return c * c * c * std::exp(-k * k * (Ts * Ts + sc2 * sc2));
}

}  // namespace roughscope
