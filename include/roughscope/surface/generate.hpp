// Random rough surfaces of known statistics (paper §3.1): Gaussian height distribution with
// Gaussian C(τ) = exp(−τ²/T²) or exponential C(τ) = exp(−|τ|/T) correlation (or any given
// isotropic PSD), made by filtering white noise in the Fourier domain (FFTW3). The surfaces are
// periodic; the ensemble ACF equals the target (periodised) on the lattice; a seed gives the same
// surface bit for bit on every run, and to FFT rounding (~1e−15) on other machines. Method and what
// is exact: docs/surface-generation.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {

struct GenerationOptions {
    Correlation correlation = Correlation::Gaussian;
    double sigma_um = 1.0;  // RMS height σ, > 0
    double T_um = 10.0;     // correlation length T, > 0
    std::size_t nx = 256;
    std::size_t ny = 256;  // 1 = a profile
    double dx_um = 1.0;
    double dy_um = 1.0;
    std::uint64_t seed = 1;
};

// InvalidArgument naming the option and its range for anything out of range, and for a grid
// whose memory (generation_memory_bytes) is above the memory budget (core/memory.hpp).
HeightMap generate_surface(const GenerationOptions& options);

// The memory one surface of the options' grid takes while it is made, in bytes (about 10 bytes a
// point: the map in its FFT buffer and the filter).
double generation_memory_bytes(const GenerationOptions& options);

// Many surfaces of the same statistics: the filter (the periodised ACF's spectrum, the costly part
// for exponential correlation) is computed once; generate(seed) then draws one surface, equal bit
// for bit to generate_surface with that seed. generate may run concurrently on one generator.
class SurfaceGenerator {
  public:
    explicit SurfaceGenerator(const GenerationOptions& options);  // validates; options.seed unused
    HeightMap generate(std::uint64_t seed) const;
    const GenerationOptions& options() const { return options_; }

  private:
    GenerationOptions options_;
    std::vector<double> gain_;  // the half-spectrum gain σ√S/(nx ny), its rows ky ≥ 0
};

// The same with the correlation replaced by an isotropic two-sided PSD W(k) of the spatial
// angular frequency k = |k| (rad/µm), scaled so that the surface's RMS height is sigma_um.
HeightMap generate_surface_from_psd(const std::function<double(double k_rad_per_um)>& psd,
                                    const GenerationOptions& options);

}  // namespace roughscope::surface
