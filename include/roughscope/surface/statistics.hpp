// Roughness statistics of a height map (paper §3.1; ISO 25178-2 / ISO 4287 names): levelling,
// the Gaussian roughness filter, height moments, autocorrelation, correlation length T, RMS slope
// and the power spectral density. Every definition, with its formula, levelling and estimator, and
// where it differs from Gwyddion's and ISO's defaults: docs/surface.md. All functions are
// mask-aware: missing (NaN) points are left out of every sum.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {

// ---- Levelling (least squares over the valid points) ---------------------------------------
enum class Leveling {
    None,        // heights as read
    Mean,        // subtract the mean height
    Line,        // subtract each row's least-squares mean line (profile practice, Gwyddion's
                 // "row levelling"); for a profile this is the paper's mean line (§3.1)
    Plane,       // subtract the least-squares plane (areal default)
    Polynomial,  // subtract a least-squares polynomial surface in x, y of total order 1..3
};
std::string to_string(Leveling leveling);
Leveling parse_leveling(std::string_view name);

// `map` minus its background. polynomial_order: 1..3, used by Leveling::Polynomial only.
// InvalidArgument when too few valid points determine the background. Pass an rvalue
// (std::move) to level in place without a copy.
HeightMap level(HeightMap map, Leveling leveling, int polynomial_order = 1);

// ---- Gaussian filter: ISO 16610-21 (profiles, along x) and ISO 16610-61 (areal) --------------
// Weighting s(x) = 1/(α λc) exp(−π (x/(α λc))²), α = sqrt(ln 2 / π): 50 % transmission of a
// sinusoid of wavelength λc. Missing points are left out with the weights renormalised.
struct FilteredHeights {
    HeightMap waviness;   // the mean surface (long wavelengths)
    HeightMap roughness;  // map − waviness (short wavelengths)
};
FilteredHeights gaussian_filter(const HeightMap& map, double cutoff_um);

// ---- Statistics -----------------------------------------------------------------------------
enum class AcfEstimator {
    Unbiased,  // C_j = (1/(N−j)) Σ z_k z_{k+j} / σ²   (paper §3.1, "unbiased")
    Biased,    // C_j = (1/N) Σ z_k z_{k+j} / σ²       (paper §3.1, "biased"; Gwyddion's)
};
std::string to_string(AcfEstimator estimator);
AcfEstimator parse_acf_estimator(std::string_view name);

struct Curve {
    std::vector<double> x;  // lag τ (µm) or spatial frequency (1/µm)
    std::vector<double> y;  // normalised ACF, or PSD (µm² · µm for 1-D, µm² · µm² for 2-D)
};

struct StatisticsOptions {
    Leveling leveling = Leveling::Plane;
    int polynomial_order = 1;
    std::optional<double> cutoff_um;  // λc of the Gaussian roughness filter; none = no filter
    AcfEstimator acf_estimator = AcfEstimator::Unbiased;
    bool keep_curves = true;  // fill acf_x, acf_y, acf_radial, psd_x, psd_radial
};

struct SurfaceStatistics {
    // Heights after levelling/filtering (µm); σ = Sq (Rq for a profile).
    std::size_t points = 0;                 // valid points used
    double sigma_um = 0;                    // Sq = sqrt((1/N) Σ z²)
    double Sa_um = 0;                       // (1/N) Σ |z|
    double Ssk = 0;                         // (1/(N σ³)) Σ z³ (0 when σ = 0)
    double Sku = 0;                         // (1/(N σ⁴)) Σ z⁴
    double Sp_um = 0;                       // max z
    double Sv_um = 0;                       // −min z (≥ 0)
    double Sz_um = 0;                       // Sp + Sv
    std::optional<double> sigma_stderr_um;  // spread of σ over rows (profile: blocks)

    // Correlation length: 1/e crossing of the ACF, interpolated between lags.
    std::optional<double> T_um;    // along x (rows)
    std::optional<double> T_y_um;  // along y (columns); none for a profile
    // Standard error of T_um from the variance of the ACF estimator at the crossing (Bartlett's
    // formula over the 2-D lags of the central lobe, delta method: docs/surface.md).
    std::optional<double> T_stderr_um;
    // Least-squares fits of each correlation function ρ(τ/T) (scattering/correlation.hpp) to the
    // ACF; the better by AIC. (Two named fields: the form the Python module's statistics
    // converter writes; fitted_T_um(c) reads them by correlation.)
    std::optional<double> T_fit_gaussian_um;
    std::optional<double> T_fit_exponential_um;
    std::optional<Correlation> correlation;  // scattering/correlation.hpp
    std::optional<double>& fitted_T_um(Correlation c) {
        return c == Correlation::Gaussian ? T_fit_gaussian_um : T_fit_exponential_um;
    }
    const std::optional<double>& fitted_T_um(Correlation c) const {
        return c == Correlation::Gaussian ? T_fit_gaussian_um : T_fit_exponential_um;
    }
    // T against 1/L over sub-profiles, extrapolated to 1/L = 0.
    std::optional<double> T_extrapolated_um;
    // A periodic component: the lag of the ACF's first maximum after a significant negative
    // swing (along x, along y); none when the ACF shows no period (docs/surface.md).
    std::optional<double> period_um;
    std::optional<double> period_y_um;
    // ISO 25178-2 with s = 0.2: fastest-decay length of the 2-D ACF and texture aspect ratio.
    std::optional<double> Sal_um;
    std::optional<double> Str;
    std::string Str_note;  // why Str is not given (empty when it is)
    // RMS slopes by forward differences: Rdq along x and along y (ISO 4287, one profile
    // direction each), and m = σ√2/T from the 1/e T.
    std::optional<double> rms_slope;
    std::optional<double> rms_slope_y;
    std::optional<double> m_from_T;

    std::vector<std::string> warnings;  // e.g. L/T < 50: the 1/e T is biased low

    // Curves for the report (empty unless StatisticsOptions::keep_curves).
    Curve acf_x, acf_y, acf_radial;
    Curve psd_x, psd_radial;

    // Areal RMS gradient Sdq = sqrt(<(∂z/∂x)²> + <(∂z/∂y)²>) by finite differences (maps only;
    // for an isotropic Gaussian surface Sdq = √2 · m, while rms_slope, along x, equals m).
    std::optional<double> Sdq;
};

// Pass the map as an rvalue (std::move) when it is not needed afterwards: it is then levelled in
// place, and the peak memory of a complete map is 6 copies of it (the map, and the 2-D ACF's
// zero-padded array of ~4), instead of 7.
SurfaceStatistics surface_statistics(HeightMap map, const StatisticsOptions& options = {});

// ---- The pieces of surface_statistics, for callers that need one of them -----------------------
// The height moments above in one pass over the map (no levelling): Sq, Sa, Ssk, Sku, Sp, Sv, Sz.
// InvalidArgument when the map has no valid point.
struct HeightMoments {
    std::size_t points = 0;
    double sigma_um = 0, Sa_um = 0, Ssk = 0, Sku = 0, Sp_um = 0, Sv_um = 0, Sz_um = 0;
};
HeightMoments height_moments(const HeightMap& map);

// Normalised ACF along x (rows) or along y (columns), the sums pooled over every row (column):
// C_j = (S_j / n_j) / (S_0 / n_0) (unbiased) or S_j / S_0 (biased), S_j = Σ z_k z_{k+j} over the
// n_j pairs of valid points j samples apart. x = j·dx (dy) for the lags with at least one pair.
// Empty when S_0 = 0 (every valid height is zero). acf_along_y of a profile is empty.
Curve acf_along_x(const HeightMap& levelled, AcfEstimator estimator);
Curve acf_along_y(const HeightMap& levelled, AcfEstimator estimator);

// The lag where the ACF first falls to 1/e, interpolated linearly between the two lags around
// the crossing; none when the curve never falls to 1/e.
std::optional<double> correlation_length_1e(const Curve& acf);

// The model autocorrelation functions of §3.1: C(τ) = exp(−τ²/T²) (Gaussian) or exp(−|τ|/T)
// (exponential), for a lag τ and a correlation length T > 0 (µm).
double acf_model(Correlation model, double lag_um, double T_um);

// Least-squares fits of C = ρ(|τ|/T) for every correlation function (scattering/correlation.hpp:
// exp(−τ²/T²), exp(−|τ|/T)) to the points of `acf` with τ ≤ max_lag_um; AIC = n ln(RSS/n) + 2k
// (k = 1 for each) names the better model (the first in kCorrelations on a tie). A fit needs 3
// points; InvalidArgument when max_lag_um is not > 0 or x and y differ in size.
struct AcfModelFit {
    std::size_t points = 0;
    PerCorrelation<std::optional<double>> T_um;  // the fitted T of each model
    PerCorrelation<double> aic;                  // its AIC
    std::optional<Correlation> better;
};
AcfModelFit fit_acf_models(const Curve& acf, double max_lag_um);

}  // namespace roughscope::surface
