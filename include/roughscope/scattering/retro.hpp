// Retro-scattering closed forms, paper §3.4 (Eq. 7–11): L = V, θi = θs = θ, φs = π.
//
// Each returns Ê_d/K (the gain K set to 1). They equal the general forms of beckmann.hpp at
// retro_geometry(θ) up to a θ-independent constant:
//   Eq. 7, 9 = Eq. 4 × 4Aσ²k²/(πT²);   Eq. 8, 10 = Eq. 5 × 4Aσ²k²/(2πT²);
//   Eq. 11  = Eq. 3 (F_VH) × A/(4πT²σ²k²).
// θ in radians, [0, π/2); lengths in µm. Inputs validated (InvalidArgument).
#pragma once

namespace roughscope {

// Eq. 7: original B–K (F_Beck), Gaussian correlation, very rough: exp(−T² tan²θ/(4σ²))/cos⁶θ.
double retro_beckmann_gaussian_very_rough(double theta_rad, double sigma_over_T);

// Eq. 8: original B–K, exponential correlation (Eq. 5): 1/(cos⁶θ [1 + (T/σ)² tan²θ]^{3/2}).
double retro_beckmann_exponential_very_rough(double theta_rad, double sigma_over_T);

// Eq. 9: V–H modified B–K, Gaussian correlation: exp(−T² tan²θ/(4σ²))/cos θ.
double retro_vh_gaussian_very_rough(double theta_rad, double sigma_over_T);

// Eq. 10: V–H modified B–K, exponential correlation: 1/(cos θ [1 + (T/σ)² tan²θ]^{3/2}).
double retro_vh_exponential_very_rough(double theta_rad, double sigma_over_T);

// Eq. 11: V–H, Gaussian correlation, slightly rough:
// cos³θ exp(−k²([T sin θ]² + [2σ cos θ]²)), k = 2π/λ.
double retro_vh_gaussian_slightly_rough(double theta_rad, double sigma_um, double T_um,
                                        double wavelength_um);

}  // namespace roughscope
