// The statue experiment of the paper's §5 (docs/photometric-stereo.md "Regions"): named regions
// of an object measured by rough-surface photometric stereo (objects/photometric_stereo.hpp)
// get the statistics of their pixels' σ/T and their roughness class, and every two regions are
// compared: do they differ in σ/T?
//
// Per region (pixels inside it with a σ/T): n, the median σ/T with its standard error
// 1.2533 · 1.4826 · MAD/√n (the median's for normal scatter, with the scatter from the median
// absolute deviation: the per-pixel fits have long tails where few lights are usable, which
// the mean and the standard deviation would follow; the pixels are taken as independent), the
// mean, the class of the median by the maps' σ/T thresholds (maps.hpp
// roughness_class_of_sigma_over_T) and the pixels per class. Comparison of regions a and b:
// z = (median_a − median_b)/√(se_a² + se_b²), two-sided p = erfc(|z|/√2); they differ when
// p < 0.05.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "roughscope/estimation/estimation.hpp"
#include "roughscope/objects/photometric_stereo.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image {

inline constexpr double kRegionsDifferP = 0.05;

struct PhotometricRegionStatistics {
    std::string name;
    std::size_t pixels = 0;                // region pixels with a normal
    std::size_t with_slope = 0;            // ... and a σ/T (the rough models)
    std::optional<Estimate> sigma_over_T;  // the median ± 1.2533 · 1.4826 · MAD/√n
    std::optional<double> mean_sigma_over_T;
    std::optional<RoughnessClass> roughness_class;  // of the median
    std::array<std::size_t, 3> class_counts{};      // pixels per class (RoughnessClass order)
    std::optional<double> median_albedo;
    std::optional<double> median_residual;
};

struct PhotometricRegionComparison {
    std::string first, second;
    double difference = 0.0;  // σ/T of first − σ/T of second (the medians)
    double difference_stderr = 0.0;
    double z = 0.0;
    double p_value = 1.0;
    bool differ = false;      // p < kRegionsDifferP
    bool same_class = false;  // both means in one roughness class
};

// labels: width · height, the region index of each pixel or −1; names: one per index. Throws
// InvalidArgument for labels of the wrong size or an index without a name.
std::vector<PhotometricRegionStatistics> photometric_region_statistics(
    const PhotometricStereoResult& result, const std::vector<std::int32_t>& labels,
    const std::vector<std::string>& names, double slightly_rough_max_sigma_over_T,
    double very_rough_min_sigma_over_T);

// Every pair (i < j) of regions with at least 2 pixels with σ/T each.
std::vector<PhotometricRegionComparison> compare_photometric_regions(
    const std::vector<PhotometricRegionStatistics>& regions);

}  // namespace roughscope::image
