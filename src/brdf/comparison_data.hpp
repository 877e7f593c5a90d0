// The data side of a BRDF comparison (paper §5.3): which measurements are used and why not, the
// used measurements as brightness values, and the two-point estimate of Table 3. Internal to the
// brdf topic (src/brdf/comparison.cpp).
#pragma once

#include <vector>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/table.hpp"

namespace roughscope::detail {

// Which measurements of `table` a comparison uses: false for a zero weight or an overflow fraction
// above the limit. Every measurement left out or doubtful (also a non-positive value, which is
// kept) gets an entry in `issues`.
std::vector<bool> select_measurements(const BrdfTable& table, const ComparisonOptions& o,
                                      std::vector<DataIssue>& issues);

// Copies the used measurements into `c` (measurement, geometry, brightness d = f cos θi, weight)
// and returns the largest brightness among them (−inf when none is used).
double copy_used_measurements(const BrdfTable& table, const std::vector<bool>& used, Comparison& c);

// σ/T from the brightness ratio of measurements o.measurement1 and o.measurement2 (Eq. 17, 19
// with F_VH), or the reason why not (a measurement missing, excluded, not viewed along the
// normal, or not positive).
TwoPointEstimate two_point_estimate(const BrdfTable& table, const std::vector<bool>& used,
                                    const ComparisonOptions& o);

}  // namespace roughscope::detail
