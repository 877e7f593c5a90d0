#include "roughscope/scattering/retro.hpp"

#include <cmath>

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

// Eq. 7
double retro_beckmann_gaussian_very_rough(double theta_rad, double sigma_over_T) {
    check_retro(theta_rad, sigma_over_T);
    const double c = std::cos(theta_rad);
    return std::exp(-slope_term(theta_rad, sigma_over_T) / 4.0) / std::pow(c, 6);
}

// Eq. 8
double retro_beckmann_exponential_very_rough(double theta_rad, double sigma_over_T) {
    check_retro(theta_rad, sigma_over_T);
    const double c = std::cos(theta_rad);
    return 1.0 / (std::pow(c, 6) * std::pow(1.0 + slope_term(theta_rad, sigma_over_T), 1.5));
}

// Eq. 9
double retro_vh_gaussian_very_rough(double theta_rad, double sigma_over_T) {
    check_retro(theta_rad, sigma_over_T);
    return std::exp(-slope_term(theta_rad, sigma_over_T) / 4.0) / std::cos(theta_rad);
}

// Eq. 10
double retro_vh_exponential_very_rough(double theta_rad, double sigma_over_T) {
    check_retro(theta_rad, sigma_over_T);
    return 1.0 / (std::cos(theta_rad) * std::pow(1.0 + slope_term(theta_rad, sigma_over_T), 1.5));
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
