// A lamp and a camera at a finite distance (roughscope/measure/finite_distance.hpp): the checks
// of the positions, each capture's geometry over its region, and the correction of the
// nominal-geometry estimators (docs/measure.md "A lamp and a camera at a finite distance").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/region/region.hpp"

namespace roughscope::image::detail {

// Whether the capture gives a lamp or a camera position; whether any capture of the request
// does.
bool has_position(const CaptureSpec& spec);
bool has_position(const MeasureRequest& request);

// Throws (DataError "<file>: <key>: <reason>" with a capture file, else InvalidArgument) unless
// the positions can be used: a sample_plane given, z > 0, a flat sample, diffuse captures only,
// and either every diffuse capture's light a position or none (a point lamp's 1/r² and a
// collimated light's unknown irradiance cannot be compared).
void check_finite_distance(const MeasureRequest& request);

// For every capture with a position: its nominal geometry at the region's centroid X0
// (spec.geometry, spec.light, spec.view) and its finite_distance (X0, the distances, the
// subsample's geometries and weights and their spread). `spans` is the region.
void locate_captures(const MeasureRequest& request, const RegionSpans& spans,
                     std::vector<CaptureMeasurement>& captures);

// Which estimate a correction belongs to, and the model B it is computed with: the very-rough
// Eq. 4/5 brightness (σ/T of `correlation`) or the diffuse term of options.regime (T given
// σ = sigma_um).
enum class CorrectedQuantity { SlopeGaussian, SlopeExponential, CorrelationLength };
struct CorrectionModel {
    CorrectedQuantity quantity = CorrectedQuantity::SlopeGaussian;
    Correlation correlation = Correlation::Gaussian;
    TwoGeometryOptions options;
    double sigma_um = 0.0;  // T given σ only
};

// f = mean_X[B(geom(X); x) (r0/r)²] / B(geom(X0); x) of capture c at the unknown x (σ/T, or T).
double correction_factor(const CaptureMeasurement& c, const CorrectionModel& model, double x);

// The ratio the nominal-geometry estimator `solve` (a ratio → the unknown x) is solved on:
// R' = (E1/E2) · (f2/f1) · (r10/r20)² at the fixed point x = solve(R'(x)), iterated from
// x0 = solve(E1/E2) to 1e-10 relative (at most 50 steps, else NoSolution). Records each
// capture's factor at the solution in its finite_distance. Without a position, E1/E2 itself.
double corrected_ratio(double ratio, const CorrectionModel& model,
                       const std::function<double(double)>& solve, CaptureMeasurement& c1,
                       CaptureMeasurement& c2);

// The recorded multiplier (f2/f1) · (r10/r20)² of `quantity` (1 when neither capture has a
// position or the factor was not recorded): the budget holds it fixed.
double ratio_correction(const CaptureMeasurement& c1, const CaptureMeasurement& c2,
                        CorrectedQuantity quantity);

// The ≥ 3-capture fit with every capture's brightness brought to its nominal geometry,
// Ẽ_k · r_k0² / f_k, each correlation with its factors at the pair's estimate of that
// correlation (`pair_slopes`: Gaussian, exponential; a missing one leaves its captures
// uncorrected).
CorrelationComparison fit_corrected(const std::vector<CaptureMeasurement*>& diffuse,
                                    const FitOptions& options,
                                    const std::array<std::optional<double>, 2>& pair_slopes);

}  // namespace roughscope::image::detail
