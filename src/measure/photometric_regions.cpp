// Regions of a photometric-stereo solution (measure/photometric_regions.hpp).
#include "roughscope/measure/photometric_regions.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image {
namespace {

// √(π/2): the median's standard error over the mean's for normal scatter; 1/Φ⁻¹(3/4): the
// standard deviation of normal scatter over its median absolute deviation.
constexpr double kMedianEfficiency = 1.2533141373155003;
constexpr double kMadToSd = 1.482602218505602;

double median_of(std::vector<double> v) {
    auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

}  // namespace

std::vector<PhotometricRegionStatistics> photometric_region_statistics(
    const PhotometricStereoResult& result, const std::vector<std::int32_t>& labels,
    const std::vector<std::string>& names, double slightly_rough_max_sigma_over_T,
    double very_rough_min_sigma_over_T) {
    const std::size_t n = result.width * result.height;
    if (labels.size() != n)
        throw InvalidArgument(concat("region labels: ", std::to_string(labels.size()),
                                     " pixels, the solution ", std::to_string(n)));
    std::vector<std::vector<double>> slope(names.size()), albedo(names.size()),
        residual(names.size());
    std::vector<PhotometricRegionStatistics> out(names.size());
    for (std::size_t r = 0; r < names.size(); ++r) out[r].name = names[r];
    const bool rough = !result.sigma_over_T.empty();
    for (std::size_t p = 0; p < n; ++p) {
        const std::int32_t label = labels[p];
        if (label < 0) continue;
        const auto r = static_cast<std::size_t>(label);
        if (r >= names.size())
            throw InvalidArgument(concat("region labels: index ", std::to_string(label),
                                         " has no name (", std::to_string(names.size()),
                                         " names)"));
        if (result.lights_used[p] < 3) continue;
        ++out[r].pixels;
        albedo[r].push_back(result.albedo[p]);
        if (std::isfinite(result.residual[p])) residual[r].push_back(result.residual[p]);
        if (rough && std::isfinite(result.sigma_over_T[p])) {
            const double s = result.sigma_over_T[p];
            slope[r].push_back(s);
            ++out[r].class_counts[static_cast<std::size_t>(roughness_class_of_sigma_over_T(
                s, slightly_rough_max_sigma_over_T, very_rough_min_sigma_over_T))];
        }
    }
    for (std::size_t r = 0; r < names.size(); ++r) {
        PhotometricRegionStatistics& s = out[r];
        if (!albedo[r].empty()) s.median_albedo = median_of(albedo[r]);
        if (!residual[r].empty()) s.median_residual = median_of(residual[r]);
        s.with_slope = slope[r].size();
        if (slope[r].empty()) continue;
        const double count = static_cast<double>(slope[r].size());
        double mean = 0.0;
        for (const double v : slope[r]) mean += v / count;
        const double median = median_of(slope[r]);
        std::vector<double> deviation;
        deviation.reserve(slope[r].size());
        for (const double v : slope[r]) deviation.push_back(std::abs(v - median));
        const double se = slope[r].size() > 1 ? kMedianEfficiency * kMadToSd *
                                                    median_of(deviation) / std::sqrt(count)
                                              : std::numeric_limits<double>::quiet_NaN();
        s.sigma_over_T = Estimate{median, se};
        s.mean_sigma_over_T = mean;
        s.roughness_class = roughness_class_of_sigma_over_T(median, slightly_rough_max_sigma_over_T,
                                                            very_rough_min_sigma_over_T);
    }
    return out;
}

std::vector<PhotometricRegionComparison> compare_photometric_regions(
    const std::vector<PhotometricRegionStatistics>& regions) {
    std::vector<PhotometricRegionComparison> out;
    for (std::size_t i = 0; i < regions.size(); ++i)
        for (std::size_t j = i + 1; j < regions.size(); ++j) {
            const PhotometricRegionStatistics& a = regions[i];
            const PhotometricRegionStatistics& b = regions[j];
            if (a.with_slope < 2 || b.with_slope < 2) continue;
            PhotometricRegionComparison c;
            c.first = a.name;
            c.second = b.name;
            c.difference = a.sigma_over_T->value - b.sigma_over_T->value;
            c.difference_stderr = std::hypot(a.sigma_over_T->std_error, b.sigma_over_T->std_error);
            c.z = c.difference_stderr > 0.0 ? c.difference / c.difference_stderr
                  : c.difference == 0.0
                      ? 0.0
                      : std::copysign(std::numeric_limits<double>::infinity(), c.difference);
            c.p_value = std::erfc(std::abs(c.z) / std::sqrt(2.0));
            c.differ = c.p_value < kRegionsDifferP;
            c.same_class = a.roughness_class == b.roughness_class;
            out.push_back(c);
        }
    return out;
}

}  // namespace roughscope::image
