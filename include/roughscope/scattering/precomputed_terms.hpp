// Geometry-only terms of the very-rough brightness (§3.1 Eq. 4 / Eq. 5 with the factors of §3.2
// and the radiometric interpretation of §3.3) and of Oren–Nayar (§5, with inter-reflection),
// computed once for a fixed set of geometries so that fits evaluate the models for many parameter
// values at the cost of one exponential (or square root) per geometry.
//
// Very rough, with m = σ/T and, per geometry k (q = v/k, see beckmann.hpp),
//   a_k = F² · rad / q_z²,   b_k = q_xy² / q_z²:
//   B_k(m) = a_k P(b_k / m²), P = very_rough_profile (correlation.hpp): exp(−t²/4) (Eq. 4),
//   (1 + t²)^{−3/2} (Eq. 5)
// the same numbers as very_rough_brightness (relative difference ≲ 1e-13, from the rounding of the
// exponential's argument), with the derivative d B_k / d ln m = B_k d ln P/d ln m in closed form
// (d_log_very_rough_profile_d_log_slope: t²/2 for Eq. 4, 3t²/(1 + t²) for Eq. 5).
//
// Oren–Nayar: L_k(σ, ρ) = ρ A_k(σ) + ρ² B_k(σ) (L1 ∝ ρ, L2 ∝ ρ², reflectance_models.hpp) with
//   A_k(σ) = (cos θi/π) (C1(σ) + c2(σ) G2_k + c3(σ) G3_k),   B_k(σ) = c4(σ) G4_k,
//   C1 = 1 − σ²/(2(σ² + 0.33)),  c2 = 0.45 σ²/(σ² + 0.09),  c3 = 0.125 σ²/(σ² + 0.09),
//   c4 = σ²/(σ² + 0.13),
// and the geometry-only G2 = cos Δφ tan β (sin α − [cos Δφ < 0] (2β/π)³),
// G3 = (1 − |cos Δφ|) (4αβ/π²)² tan((α + β)/2), G4 = 0.17 (cos θi/π) (1 − cos Δφ (2β/π)²):
// oren_nayar_radiance to rounding (relative difference ≲ 1e-15).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

namespace roughscope {

class VeryRoughTerms {
  public:
    VeryRoughTerms() = default;
    // Validates every geometry (check::geometry, "geometry <k>" in the message).
    VeryRoughTerms(std::span<const Geometry> geoms, GeometricFactor factor, Radiometry radiometry);

    std::size_t size() const { return a_.size(); }

    // out[k] = very-rough brightness at geometry k (out.size() == size()); σ/T > 0 (checked).
    void brightness(double sigma_over_T, Correlation correlation, std::span<double> out) const;
    // The same and d out[k] / d ln(σ/T) (both of size()).
    void brightness_and_log_derivative(double sigma_over_T, Correlation correlation,
                                       std::span<double> out,
                                       std::span<double> d_out_d_ln_sigma_over_T) const;

  private:
    std::vector<double> a_, b_;
};

class OrenNayarTerms {
  public:
    OrenNayarTerms() = default;
    // Validates every geometry (check::geometry, "geometry <k>" in the message).
    explicit OrenNayarTerms(std::span<const Geometry> geoms);

    std::size_t size() const { return p0_.size(); }

    // The σ-only factors of A_k and B_k (file comment); σ ≥ 0 (checked).
    struct Coefficients {
        double C1 = 0.0, c2 = 0.0, c3 = 0.0, c4 = 0.0;
    };
    static Coefficients coefficients(double sigma_rad);
    // A_k(σ) and B_k(σ) one geometry at a time (no N-sized buffer), the numbers components gives.
    double term_a(std::size_t k, const Coefficients& c) const {
        return p0_[k] * (c.C1 + c.c2 * g2_[k] + c.c3 * g3_[k]);
    }
    double term_b(std::size_t k, const Coefficients& c) const { return c.c4 * g4_[k]; }
    // A_k(σ) and B_k(σ) of the file comment (sizes size()); σ ≥ 0 (checked).
    void components(double sigma_rad, std::span<double> A, std::span<double> B) const;
    // out[k] = oren_nayar_radiance(geometry k, params); parameters checked as there.
    void radiance(const OrenNayarParams& params, std::span<double> out) const;

  private:
    std::vector<double> p0_, g2_, g3_, g4_;
};

}  // namespace roughscope
