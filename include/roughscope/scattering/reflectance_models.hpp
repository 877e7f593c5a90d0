// Comparison reflectance models used in the paper's §5 (Lambert, Oren–Nayar, Lafortune).
//
// All take a Geometry in the paper's frame (geometry.hpp) and return pixel brightness up to a
// gain, i.e. scene radiance for unit irradiance E0 = 1 along the light direction. Inputs are
// validated (InvalidArgument naming the input and range). Directions below the horizon are not
// representable (θ < 90° is enforced); a Lafortune lobe whose cosine is negative gives 0.
#pragma once

#include <vector>

#include "roughscope/scattering/geometry.hpp"

namespace roughscope {

// Lambert's cosine law: E ∝ cos θi (albedo and gain dropped). θi in [0, π/2).
double lambert_brightness(double theta_i_rad);

// Oren–Nayar (1994) parameters: σ is the standard deviation of the facet slope angle in radians
// (≥ 0), ρ the facet albedo in [0, 1].
struct OrenNayarParams {
    double sigma_rad = 0.0;
    double albedo = 1.0;
};

// σ²/(σ² + c), the saturating factor of every Oren–Nayar coefficient (c = 0.33, 0.09, 0.13),
// without inf/inf when σ² overflows: → 1 as σ → ∞.
inline double oren_nayar_saturation(double s2, double c) {
    return s2 > 1.0 ? 1.0 / (1.0 + c / s2) : s2 / (s2 + c);
}

// Full Oren–Nayar model with the inter-reflection term (Oren & Nayar, SIGGRAPH 1994, Eq. 30
// plus the L2 term): L = L1 + L2 with
//   L1 = (ρ/π) cos θi [C1 + cos(φr−φi) C2 tan β + (1 − |cos(φr−φi)|) C3 tan((α+β)/2)]
//   L2 = 0.17 (ρ²/π) cos θi σ²/(σ²+0.13) [1 − cos(φr−φi) (2β/π)²]
// α = max(θi, θs), β = min(θi, θs); in the paper's frame cos(φr−φi) = cos(φs − π) = −cos φs.
// σ = 0 gives Lambert: (ρ/π) cos θi.
double oren_nayar_radiance(const Geometry& geom, const OrenNayarParams& params);

// Qualitative Oren–Nayar model: (ρ/π) cos θi [A + B max(0, cos(φr−φi)) sin α tan β],
// A = 1 − 0.5 σ²/(σ²+0.33), B = 0.45 σ²/(σ²+0.09).
double oren_nayar_qualitative_radiance(const Geometry& geom, const OrenNayarParams& params);

// One generalised-cosine lobe of Lafortune et al. (1997): ρ [Cx Lx Vx + Cy Ly Vy + Cz Lz Vz]^n
// with L, V the unit light and view vectors of geometry.hpp; 0 where the bracket is ≤ 0.
struct LafortuneLobe {
    double Cx = 0.0;
    double Cy = 0.0;
    double Cz = 1.0;
    double n = 1.0;       // exponent, > 0
    double albedo = 1.0;  // lobe scale ρ, ≥ 0
};

// Lafortune BRDF: rho_d/π + Σ lobes. rho_d ≥ 0.
double lafortune_brdf(const Geometry& geom, const std::vector<LafortuneLobe>& lobes,
                      double rho_d = 0.0);

// The diffuse lobe the paper fits to CUReT (Cx = Cy = 0, Cz = 1): brightness
// E ∝ f cos θi = (cos θi cos θs)^n cos θi.
double lafortune_diffuse_brightness(const Geometry& geom, double n);

}  // namespace roughscope
