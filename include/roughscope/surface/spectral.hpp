// The FFT side of the height statistics (FFTW3): the 2-D autocorrelation by zero-padded FFT (no
// wrap-around), its radial average, the ISO 25178-2 texture parameters Sal and Str, and the 1-D
// and radially averaged 2-D power spectral density. Inputs are levelled maps (statistics.hpp);
// missing points count as absent (their products are left out and the normalisation counts only
// valid pairs). Definitions: docs/surface-generation.md.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface {

// Normalised 2-D ACF C(τx, τy) on the lags −(nx−1)..(nx−1) × −(ny−1)..(ny−1); C(0, 0) = 1.
struct Acf2d {
    std::size_t nx = 0;  // 2·map.nx − 1
    std::size_t ny = 0;  // 2·map.ny − 1
    double dx_um = 1.0;
    double dy_um = 1.0;
    std::vector<double> values;  // row-major, lag (0, 0) at (nx/2, ny/2)
    double at_lag(std::ptrdiff_t jx, std::ptrdiff_t jy) const {
        return values[static_cast<std::size_t>(jy + static_cast<std::ptrdiff_t>(ny / 2)) * nx +
                      static_cast<std::size_t>(jx + static_cast<std::ptrdiff_t>(nx / 2))];
    }
};

// C = NaN at a lag without any pair of valid points. InvalidArgument for a malformed map or one
// whose heights are all 0 (σ = 0: no ACF).
Acf2d acf_2d(const HeightMap& levelled, AcfEstimator estimator);
// Average of C over rings of width min(dx, dy); x = τ (µm).
Curve radial_acf(const Acf2d& acf);

struct TextureParameters {
    std::optional<double> Sal_um;  // shortest lag at which C falls to s
    std::optional<double> Str;     // Sal / longest such lag (0..1)
    // Of the directions searched (a map: 360 over [0°, 180°) from +x), those whose ACF stays above
    // s to the edge of the lag grid (then Str is undefined), and the first of them (degrees).
    int directions = 0;
    int directions_without_crossing = 0;
    std::optional<double> first_without_crossing_deg;
};
TextureParameters texture_parameters(const Acf2d& acf, double s = 0.2);

// One-sided PSD along x averaged over rows, and the radially averaged 2-D PSD; x = spatial
// frequency (1/µm), normalised so that the integral of the PSD over frequency is σ²
// (σ² = (1/N_valid) Σ z²): Σ_k W(f_k) Δf for psd_x, ∫ W(f) 2πf df over the frequency plane for
// psd_radial. Missing points are zero-filled. psd_radial throws InvalidArgument for a profile.
Curve psd_x(const HeightMap& levelled);
Curve psd_radial(const HeightMap& levelled);

}  // namespace roughscope::surface
