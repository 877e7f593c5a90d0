// Internal to the image topic: what measure() (image/measure.hpp) says about its numbers — the
// form of T given σ chosen at the sample's g, standard errors the captures cannot give, and what
// an exponential σ/T rests on (docs/measure.md "What is computed").
#pragma once

#include <optional>
#include <string>

#include "roughscope/measure/measure.hpp"

namespace roughscope::image::detail {

// The regime of T given σ at two geometries: the request's when given, else the form valid at
// the sample's g (the larger g = σ² v_z² of the two): Regime::SlightlyRough (Eq. 3, Eq. 15 at
// normal view) where g < kSlightlyRoughMaxG, Regime::Series (the exact sum, any g) elsewhere.
Regime correlation_length_regime(const std::optional<Regime>& given, double sigma_um,
                                 const Geometry& geom1, const Geometry& geom2,
                                 double wavelength_um);

// The larger g = σ² v_z² of the two geometries.
double largest_g(double sigma_um, const Geometry& geom1, const Geometry& geom2,
                 double wavelength_um);

// Marks a standard error unknown (NaN; the JSON writes null).
void mark_unknown(std::optional<Estimate>& e);

// Marks unknown the standard errors of an estimate that depend on a brightness ratio whose noise
// is unknown: σ/T, T and the quantities derived from σ/T (m, θK, ξK); σ too with `sigma_too`
// (σ estimated from the same unknown noise).
void mark_unknown_errors(RoughnessEstimate& e, bool sigma_too);

// The note every result with an exponential σ/T carries: Eq. 19 (and the solver, the fits and
// the retro forms of the exponential correlation) rest on the paper's Eq. 5, which the exact
// Kirchhoff series contradicts (docs/exponential-correlation.md).
std::string exponential_note();

// Whether the result holds an exponential σ/T (the pair's, the fit's, the cylinder profile's or
// the map's).
bool has_exponential_sigma_over_T(const MeasureResult& result);

}  // namespace roughscope::image::detail
