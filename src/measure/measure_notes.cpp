// What measure() says about its numbers (measure_notes.hpp).
#include "measure_notes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image::detail {

double largest_g(double sigma_um, const Geometry& geom1, const Geometry& geom2,
                 double wavelength_um) {
    return std::max(roughness_g(geom1, sigma_um, wavelength_um),
                    roughness_g(geom2, sigma_um, wavelength_um));
}

Regime correlation_length_regime(const std::optional<Regime>& given, double sigma_um,
                                 const Geometry& geom1, const Geometry& geom2,
                                 double wavelength_um) {
    if (given) return *given;
    // §3.1: Eq. 3 (and so Eq. 15) is the first term of Eq. 2, accurate for g ≪ 1 only; the
    // series holds at every g (validity.hpp draws the slightly rough line at g = 0.1).
    return largest_g(sigma_um, geom1, geom2, wavelength_um) < kSlightlyRoughMaxG
               ? Regime::SlightlyRough
               : Regime::Series;
}

void mark_unknown(std::optional<Estimate>& e) {
    if (e) e->std_error = std::numeric_limits<double>::quiet_NaN();
}

void mark_unknown_errors(RoughnessEstimate& e, bool sigma_too) {
    if (sigma_too) mark_unknown(e.sigma_um);
    mark_unknown(e.T_um);
    mark_unknown(e.sigma_over_T);
    mark_unknown(e.rms_slope);
    mark_unknown(e.theta_K_rad);
    mark_unknown(e.xi_K);
}

std::string exponential_note() {
    return "σ/T (exponential) is the paper's Eq. 19 (for other geometries, fits and profiles the "
           "same Eq. 5 as published), and the exact Kirchhoff series of an exponential "
           "correlation does not tend to Eq. 5 at any g: the value is the σ/T of Eq. 5's lobe "
           "that matches the brightness (comparable with the paper's Table 2), not the σ/T of an "
           "exponentially correlated surface, whose very-rough lobe depends on σ²/(Tλ) rather "
           "than on σ/T (docs/exponential-correlation.md)";
}

bool has_exponential_sigma_over_T(const MeasureResult& r) {
    if (r.slope_exponential && r.slope_exponential->sigma_over_T) return true;
    if (r.fit && !r.fit->exponential.parameters.empty()) return true;
    if (r.cylinder && r.cylinder->exponential_fit.sigma_over_T) return true;
    // T given σ from Eq. 5 itself (regime very_rough, exponential correlation).
    if (r.correlation_length && r.correlation_length->correlation == Correlation::Exponential &&
        r.correlation_length_regime == Regime::VeryRough)
        return true;
    if (r.map) {
        if (!r.map->sigma_over_T_exponential.empty()) return true;
        for (const RegionMapStatistics& region : r.map->regions)
            if (region.mean_sigma_over_T_exponential) return true;
    }
    return false;
}

}  // namespace roughscope::image::detail
