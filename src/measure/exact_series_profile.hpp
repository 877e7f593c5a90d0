// Profile-likelihood 95 % intervals of the exact-series joint fit (exact_series.cpp): for each
// of σ, T and σ/T, the values where χ² minimised over the other parameter (the gain profiled out
// by linear least squares) is within the χ²(1) 95 % quantile of its minimum. Where the captures do
// not determine a parameter (the region reaches the edge of the searched range) its interval is
// open on that side.
#pragma once

#include <vector>

#include "roughscope/fit/fit.hpp"

namespace roughscope::image::detail {

struct ProfileInterval {
    double low = 0.0;
    double high = 0.0;
    bool open_low = false;   // the region reaches the low end of the range searched
    bool open_high = false;  // ... the high end
};

struct ProfileIntervals {
    bool ok = false;
    ProfileInterval sigma_um, T_um, sigma_over_T;
    double chi2_min = 0.0;
    double threshold = 0.0;                       // Δχ²: 3.84 × max(1, χ²_min/(N − 3))
    double best_sigma_um = 0.0, best_T_um = 0.0;  // the σ profile's minimum (or the fit's)
};

// χ²(σ, T) = Σ w_i (K B_i/E_i − 1)², K by weighted least squares (the fit's relative residuals
// with weights 1/e_i²); each profile on 81 log-spaced points over σ0 × [1/100, 100] (T0, σ0/T0
// likewise, within the options' bounds), the free parameter minimised by a 25-point scan and
// golden sections. The threshold is 3.84 × max(1, χ²_min/(N − 3)).
ProfileIntervals profile_intervals(const std::vector<Measurement>& data, const FitOptions& options,
                                   double sigma0_um, double T0_um);

}  // namespace roughscope::image::detail
