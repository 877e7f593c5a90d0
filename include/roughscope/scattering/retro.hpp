// Retro-scattering closed forms, paper §3.4 (Eq. 7–11): L = V, θi = θs = θ, φs = π.
//
// Each returns Ê_d/K (the gain K set to 1). They equal the general forms of beckmann.hpp at
// retro_geometry(θ) up to a θ-independent constant:
//   Eq. 7, 9 = Eq. 4 × 4Aσ²k²/(πT²);   Eq. 8, 10 = Eq. 5 × 4Aσ²k²/(2πT²);
//   Eq. 11  = Eq. 3 (F_VH) × A/(4πT²σ²k²).
// θ in radians, [0, π/2); lengths in µm. Inputs validated (InvalidArgument).
#pragma once

#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope {

// Eq. 7–10, very rough: P((T/σ)² tan²θ)/cos⁶θ with F_Beck (Eq. 7 Gaussian, Eq. 8 exponential)
// or P((T/σ)² tan²θ)/cos θ with F_VH (Eq. 9, Eq. 10), P = very_rough_profile (correlation.hpp):
// exp(−t²/4) or (1 + t²)^{−3/2}. factor must be Beckmann or VernoldHarvey (else InvalidArgument).
double retro_very_rough(Correlation correlation, GeometricFactor factor, double theta_rad,
                        double sigma_over_T);

// Eq. 11: V–H, Gaussian correlation, slightly rough:
// cos³θ exp(−k²([T sin θ]² + [2σ cos θ]²)), k = 2π/λ.
double retro_vh_gaussian_slightly_rough(double theta_rad, double sigma_um, double T_um,
                                        double wavelength_um);

// The two-name forms kept for the photograph, CLI and Python code; they forward to
// retro_very_rough.
inline double retro_beckmann_gaussian_very_rough(double theta_rad, double sigma_over_T) {  // Eq. 7
    return retro_very_rough(Correlation::Gaussian, GeometricFactor::Beckmann, theta_rad,
                            sigma_over_T);
}
inline double retro_beckmann_exponential_very_rough(double theta_rad,
                                                    double sigma_over_T) {  // Eq. 8
    return retro_very_rough(Correlation::Exponential, GeometricFactor::Beckmann, theta_rad,
                            sigma_over_T);
}
inline double retro_vh_gaussian_very_rough(double theta_rad, double sigma_over_T) {  // Eq. 9
    return retro_very_rough(Correlation::Gaussian, GeometricFactor::VernoldHarvey, theta_rad,
                            sigma_over_T);
}
inline double retro_vh_exponential_very_rough(double theta_rad, double sigma_over_T) {  // Eq. 10
    return retro_very_rough(Correlation::Exponential, GeometricFactor::VernoldHarvey, theta_rad,
                            sigma_over_T);
}

}  // namespace roughscope
