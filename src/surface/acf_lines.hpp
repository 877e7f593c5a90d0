// Internal: autocorrelation sums of many lines (rows, columns, sub-profiles) of a height map,
// by zero-padded FFT (fft_rows.hpp), pooled over the lines and optionally kept per line; shared
// by acf.cpp and statistics.cpp.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "roughscope/core/text.hpp"
#include "roughscope/surface/spectral.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface::detail {

class RowFft;

// The normalised C_j from the sums S_j and pair counts n_j (C_0 = 1); NaN where n_j = 0.
double acf_value(const std::vector<double>& sums, const std::vector<double>& pairs, std::size_t j,
                 AcfEstimator estimator);

// The 1/e crossing in samples from the sums (linear interpolation between lags), or none.
// `pairs` null: every pair present (n_j = n − j).
std::optional<double> crossing_1e_samples(const double* sums, const double* pairs, std::size_t n,
                                          AcfEstimator estimator);
std::optional<double> crossing_1e_samples(const std::vector<double>& sums,
                                          const std::vector<double>& pairs, AcfEstimator estimator);

// Adds lines of `length` samples (NaN = missing) one at a time:
//   sums[j]  = Σ_lines Σ_k z_k z_{k+j}     over valid pairs,
//   pairs[j] = Σ_lines (number of valid pairs j apart),
// and, when per_line is set, each line's rms height and 1/e crossing (samples).
class LineAcf {
  public:
    LineAcf(std::size_t length, AcfEstimator estimator, bool per_line);
    ~LineAcf();
    LineAcf(const LineAcf&) = delete;
    LineAcf& operator=(const LineAcf&) = delete;
    LineAcf(LineAcf&&) = delete;
    LineAcf& operator=(LineAcf&&) = delete;

    void add(const double* z);
    // Pooled sums (call once, after the last add).
    void finish();

    std::size_t length() const { return length_; }
    std::vector<double> sums;
    std::vector<double> pairs;
    std::vector<double> line_rms_um;         // lines with a valid point
    std::vector<double> line_crossing;       // lines whose ACF crosses 1/e (samples)
    std::size_t lines_without_crossing = 0;  // lines with data whose ACF never reaches 1/e

  private:
    void record_line(double sum_sq, std::size_t valid, const double* line_sums,
                     const double* line_pairs);
    std::size_t length_;
    AcfEstimator estimator_;
    bool per_line_;
    std::size_t full_lines_ = 0;  // lines without a missing point: pairs = length − j
    std::unique_ptr<RowFft> fft_;
    std::vector<double> line_sums_, line_pairs_;
};

// Row (x) and column (y) sums of a map.
void accumulate_rows(const HeightMap& map, LineAcf& acc);
void accumulate_columns(const HeightMap& map, LineAcf& acc);

// The curve C(j·spacing) for the lags with pairs; empty when S_0 = 0.
Curve acf_curve(const LineAcf& acc, AcfEstimator estimator, double spacing_um);

// ---- The ACF's shape beyond the 1/e crossing (acf_shape.cpp) ---------------------------------
// C at `lag_um` interpolated linearly between the curve's lags; NaN outside them.
double curve_value(const Curve& acf, double lag_um);

// The last lag (samples) before the ACF first falls to 0 — its central lobe — capped at
// lobe_over_T · T when T is known; the curve's last lag when it never falls to 0.
std::size_t central_lobe_samples(const Curve& acf, double spacing_um, std::optional<double> T_um,
                                 double lobe_over_T);

// A profile's ACF curve on a 1-row lag grid (C(−τ) = C(τ); NaN at lags without pairs).
Acf2d profile_lag_grid(const Curve& acf, double spacing_um);

// Bartlett's sums over the lags Δ of the window |Δx| ≤ window_x, |Δy| ≤ window_y (ρ = 0 outside
// it), for the shift h = (shift_x, 0) where ρ(h) = rho_shift:
//   s0 = Σ ρ(Δ)²
//   sh = Σ [ρ(Δ)² + ρ(Δ+h) ρ(Δ−h) − 4 ρ(h) ρ(Δ) ρ(Δ−h) + 2 ρ(h)² ρ(Δ)²]
// each term weighted by (1 − |Δx|/nx)(1 − |Δy|/ny), the share of the map's pairs Δ apart (nx, ny:
// the map's size, from the lag grid's), so that var ρ̂(h) ≈ sh / n_h over n_h pairs, and ≈ s0 / n_h
// where ρ ≈ 0 around h.
struct BartlettSums {
    double s0 = 0;
    double sh = 0;
};
BartlettSums bartlett_sums(const Acf2d& rho, std::size_t window_x, std::size_t window_y,
                           std::size_t shift_x, double rho_shift);

// A periodic ACF: after its first zero crossing τ0 it falls to `low` ≤ −threshold (the minimum
// over [τ0, 3 τ0]) and rises again to `high` ≥ threshold at period_um, an interior maximum over
// [1.5, 2.5] × the minimum's lag (≤ max_lag_um; parabolic refinement); none otherwise.
struct AcfSwing {
    double low = 0, low_lag_um = 0;
    double high = 0, period_um = 0;
};
std::optional<AcfSwing> find_period(const Curve& acf, double max_lag_um, double threshold);

}  // namespace roughscope::surface::detail
