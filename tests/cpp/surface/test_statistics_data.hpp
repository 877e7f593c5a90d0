// Test data for the surface statistics tests: random maps with a fixed seed, profiles of known
// autocorrelation (AR(1): exponential; white noise smoothed by a Gaussian kernel: Gaussian).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface::testdata {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Standard normal deviates from a fixed seed (Box–Muller on mt19937_64, so the sequence is the
// same with every standard library).
class Normal {
  public:
    explicit Normal(std::uint64_t seed) : engine_(seed) {}
    double operator()() {
        const double u1 = (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
        const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }

  private:
    std::mt19937_64 engine_;
};

// White noise map with a fraction of missing points.
inline HeightMap noise_map(std::size_t nx, std::size_t ny, std::uint64_t seed,
                           double missing_fraction = 0.0) {
    HeightMap map = make_height_map(nx, ny, 0.5, 0.75);
    Normal normal(seed);
    std::mt19937_64 pick(seed + 1);
    for (double& z : map.heights_um) {
        z = normal();
        if (static_cast<double>(pick() >> 11) * 0x1.0p-53 < missing_fraction) z = kNaN;
    }
    return map;
}

// One AR(1) line z_k = φ z_{k−1} + sqrt(1 − φ²) e_k, φ = exp(−1/T): ensemble ACF exp(−j/T),
// σ = 1 (T in samples).
inline void ar1_line(double* z, std::size_t n, double T_samples, Normal& normal) {
    const double phi = std::exp(-1.0 / T_samples);
    const double s = std::sqrt(1.0 - phi * phi);
    double prev = normal();
    for (std::size_t k = 0; k < n; ++k) {
        prev = phi * prev + s * normal();
        z[k] = prev;
    }
}

// Rows of independent AR(1) lines.
inline HeightMap ar1_map(std::size_t nx, std::size_t ny, double T_samples, std::uint64_t seed,
                         double dx_um = 1.0) {
    HeightMap map = make_height_map(nx, ny, dx_um, dx_um);
    Normal normal(seed);
    for (std::size_t iy = 0; iy < ny; ++iy)
        ar1_line(&map.heights_um[iy * nx], nx, T_samples, normal);
    return map;
}

// White noise convolved with exp(−k²/a²), a = T/√2: ensemble ACF exp(−j²/T²) (T in samples).
inline HeightMap gaussian_profile(std::size_t n, double T_samples, std::uint64_t seed,
                                  double dx_um = 1.0) {
    const double a = T_samples / std::sqrt(2.0);
    const auto half = static_cast<std::ptrdiff_t>(std::ceil(6 * a));
    std::vector<double> kernel;
    for (std::ptrdiff_t k = -half; k <= half; ++k)
        kernel.push_back(std::exp(-static_cast<double>(k * k) / (a * a)));
    Normal normal(seed);
    std::vector<double> noise(n + kernel.size());
    for (double& e : noise) e = normal();
    HeightMap map = make_height_map(n, 1, dx_um, dx_um);
    for (std::size_t i = 0; i < n; ++i) {
        double s = 0;
        for (std::size_t k = 0; k < kernel.size(); ++k) s += kernel[k] * noise[i + k];
        map.heights_um[i] = s;
    }
    return map;
}

}  // namespace roughscope::surface::testdata
