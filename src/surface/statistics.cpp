// Placeholder: implemented by the surface-statistics work (see statistics.hpp).
#include "roughscope/surface/statistics.hpp"

#include "roughscope/core/errors.hpp"

namespace roughscope::surface {
std::string to_string(Leveling) { return "plane"; }
Leveling parse_leveling(std::string_view) { return Leveling::plane; }
std::string to_string(AcfEstimator) { return "unbiased"; }
AcfEstimator parse_acf_estimator(std::string_view) { return AcfEstimator::unbiased; }
HeightMap level(const HeightMap& map, Leveling, int) { return map; }
FilteredHeights gaussian_filter(const HeightMap& map, double) { return {map, map}; }
SurfaceStatistics surface_statistics(const HeightMap&, const StatisticsOptions&) {
    throw InvalidArgument("surface statistics are not available yet");
}
}  // namespace roughscope::surface
