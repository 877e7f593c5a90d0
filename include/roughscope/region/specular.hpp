// The specular highlight measurement of paper §4.1.1 (and §5.1): Ẽ_tot, the brightness at the
// centre of the specular highlight, and Ẽ_dif, the diffuse brightness in the neighbourhood of
// the specular lobe, for R_spec = 1 − Ẽ_dif / Ẽ_tot and σ from Eq. (13) (estimation topic).
//
// Coordinates are the region convention (region.hpp): pixel (i, j) has its centre at
// (i + ½, j + ½). The rules (search, width, radii) are in docs/image-regions.md.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "roughscope/photo/image.hpp"
#include "roughscope/region/statistics.hpp"

namespace roughscope::image {

struct HighlightOptions {
    // Gaussian smoothing (σ in px) of the channel-average image before the peak search; 0: none.
    double smoothing_sigma_px = 2.0;
    // Unset: chosen from the highlight's half width at half maximum w (width_px):
    //   core = max(1.5, w / 4), annulus_inner = max(3 w, core + 2), annulus_outer =
    //   max(4 w, annulus_inner + 3), in px. The core is the disc d ≤ core, the annulus
    //   annulus_inner < d ≤ annulus_outer (d: distance of a pixel centre from the centre).
    std::optional<double> core_radius_px, annulus_inner_px, annulus_outer_px;
    // Given: the highlight centre (x, y) in px; the peak search is skipped.
    std::optional<std::array<double, 2>> centre_px;
    // For the core and annulus statistics.
    RegionStatisticsOptions statistics;
};

struct HighlightMeasurement {
    double centre_x_px = 0, centre_y_px = 0;  // sub-pixel centre (or the given one)
    double core_radius_px = 0, annulus_inner_px = 0, annulus_outer_px = 0;  // used
    // Half width at half maximum above the surround, from the radial profile of the channel
    // average (unsmoothed) about the centre.
    double width_px = 0;
    RegionStatistics core, annulus;  // Ẽ_tot (core), Ẽ_dif (annulus)
    double E_tot = 0, E_dif = 0;     // average-channel means of core and annulus
    // max(stderr_pixel, stderr_tiles) / mean, of the average channel.
    double E_tot_relative_stderr = 0, E_dif_relative_stderr = 0;
    std::vector<std::string> warnings;  // the core's and annulus's, and the measurement's own
};

// Throws InvalidArgument unless smoothing_sigma_px is finite and ≥ 0 (at most 100), the given
// radii are finite and > 0 with core ≤ annulus_inner < annulus_outer (among those given), the
// given centre is finite, and the statistics options are valid.
void check_highlight_options(const HighlightOptions& options);

// Measures the specular highlight inside `region_mask` (one byte per pixel, nonzero = inside, as
// rasterize() returns). The peak is the maximum of the smoothed channel average over the region
// (saturated pixels included: they locate the highlight; they never enter the statistics),
// refined to sub-pixel by a parabola through it and its neighbours. Core and annulus are
// restricted to the region. Throws InvalidArgument for an inconsistent image or mask, invalid
// options, a peak on the border of the region or the image, a given centre outside the image, a
// core or annulus with no usable pixel (or mostly flagged: options.statistics), and a core or
// annulus mean ≤ 0.
HighlightMeasurement measure_highlight(const LinearImage& image,
                                       const std::vector<std::uint8_t>& region_mask,
                                       const HighlightOptions& options = {});

}  // namespace roughscope::image
