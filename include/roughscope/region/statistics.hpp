// Brightness statistics of an image region: the averaged pixel brightness the estimators of the
// paper take (§4.1: Ẽ_tot, Ẽ_dif; §4.1.2: E_d "averaged over a neighbourhood so that the effects
// of rough surface texture are smoothed away"), with two standard errors: one from pixel noise and
// one from the spread of tile means, which also sees texture and shading. Formulas in
// docs/image-regions.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "roughscope/photo/image.hpp"
#include "roughscope/region/region.hpp"

namespace roughscope::image {

// Statistics of one series of values (the used pixels of one plane, or of the channel average).
struct ChannelStatistics {
    double mean = 0;          // Σ v / n
    double robust_mean = 0;   // Huber M-estimate, k = 1.345, scale = 1.4826 · MAD (above 2^20
                              // pixels: of a regular subsample of 2^20, docs/image-regions.md)
    double std_dev = 0;       // √(Σ (v − mean)² / (n − 1)); 0 for n = 1
    double stderr_pixel = 0;  // std_dev / √n
    double stderr_tiles = 0;  // std of tile means / √tiles (0 when tiles < 2)
    std::size_t count = 0;    // n: pixels used
    std::size_t tiles = 0;    // tiles that count (≥ half their pixels used)
};

struct RegionStatistics {
    std::vector<ChannelStatistics> channels;  // per plane (1 grey, 3 R, G, B)
    // Of the per-pixel channel average (R + G + B) / 3 (the paper's RGB average); equal to
    // channels[0] for a grey image.
    ChannelStatistics average;
    std::size_t pixels_in_region = 0;    // mask pixels
    std::size_t pixels_used = 0;         // mask pixels with no flag
    std::size_t pixels_saturated = 0;    // mask pixels with kPixelSaturated
    std::size_t pixels_clipped_low = 0;  // mask pixels with kPixelClippedLow
    std::size_t tile_size_px = 0;        // the tile side used
    std::vector<std::string> warnings;   // flagged pixels left out; too few tiles (always last)
};

struct RegionStatisticsOptions {
    // Side of the square tiles (image grid, origin at the top-left corner). 0: chosen, the
    // largest of t0, ⌊0.8 t0⌋, ⌊0.8² t0⌋, ... ≥ 4 for which ≥ 16 tiles count, with
    // t0 = max(4, ⌊√(pixels_used / 32)⌋) (a compact region then holds ≈ 16–32 tiles); 4 when none.
    std::size_t tile_size_px = 0;
    // More flagged pixels than this fraction of the region → InvalidArgument ("mostly saturated").
    double max_excluded_fraction = 0.5;
    // More than this fraction (and not more than max_excluded_fraction) → a warning with the
    // counts. The default 0 warns about any flagged pixel.
    double warn_excluded_fraction = 0.0;
};

// Throws InvalidArgument unless both fractions are finite and in [0, 1].
void check_region_statistics_options(const RegionStatisticsOptions& options);

// Statistics of the pixels of `image` where mask is nonzero (mask: one byte per pixel, row-major,
// as rasterize() returns). A pixel with any flag bit set (saturated, clipped low, or any other
// bit) is never averaged in. Throws InvalidArgument for an inconsistent image
// (check_linear_image_layout), a non-finite value at a used pixel (a value that is never read —
// outside the region or flagged — is not checked), a mask whose size is not the image's, an empty
// region, a region with no usable pixel, or more flagged pixels than
// options.max_excluded_fraction.
RegionStatistics region_statistics(const LinearImage& image, const std::vector<std::uint8_t>& mask,
                                   const RegionStatisticsOptions& options = {});
// The same for the region as spans (region_spans: no mask is read); InvalidArgument when the
// spans are of an image of another size.
RegionStatistics region_statistics(const LinearImage& image, const RegionSpans& region,
                                   const RegionStatisticsOptions& options = {});

}  // namespace roughscope::image
