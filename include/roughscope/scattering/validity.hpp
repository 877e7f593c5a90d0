// Limits of validity (paper §3.5) and the roughness classes of §3.1.
#pragma once

#include <cmath>
#include <string_view>

#include "roughscope/scattering/geometry.hpp"

namespace roughscope {

// §3.1: surfaces are slightly rough for g ≪ 1, moderately rough for g ≈ 1, very rough for g ≫ 1.
// The library draws the lines one decade either side of g = 1:
//   g < kSlightlyRoughMaxG (0.1)  → SlightlyRough   (at v_xy = 0, Eq. 3 is within 2.5 % of Eq. 2)
//   g > kVeryRoughMinG (10)       → VeryRough       (at v_xy = 0, Eq. 4 is within 12 % of Eq. 2,
//                                                    and the gap shrinks like 1/g)
//   otherwise                     → ModeratelyRough (only the full series is accurate)
inline constexpr double kSlightlyRoughMaxG = 0.1;
inline constexpr double kVeryRoughMinG = 10.0;

enum class RoughnessClass { SlightlyRough, ModeratelyRough, VeryRough };

inline RoughnessClass roughness_class(double g) {
    if (g < kSlightlyRoughMaxG) return RoughnessClass::SlightlyRough;
    if (g > kVeryRoughMinG) return RoughnessClass::VeryRough;
    return RoughnessClass::ModeratelyRough;
}

std::string_view to_string(RoughnessClass c);  // "slightly_rough", "moderately_rough", "very_rough"
RoughnessClass parse_roughness_class(std::string_view name);  // throws InvalidArgument

// RMS slope m = σ√2/T (§4; also called the RMS gradient σ_g). Gaussian correlation.
inline double rms_slope(double sigma_over_T) { return std::sqrt(2.0) * sigma_over_T; }

// Caron's angle of RMS slope θK = π/2 − atan(σ√2/T) (§3.5): incidence angles above it are outside
// the model's validity (shadowing). Gaussian height distribution and correlation.
inline double caron_theta_K_rad(double sigma_over_T) {
    return kPi / 2.0 - std::atan(rms_slope(sigma_over_T));
}

// Caron's energy conservation rate at normal incidence, g ≫ 1: ξK = 1 − exp(−T²/4σ²) (§3.5).
inline double caron_xi_K(double sigma_over_T) {
    return -std::expm1(-1.0 / (4.0 * sigma_over_T * sigma_over_T));
}

}  // namespace roughscope
