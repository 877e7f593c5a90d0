// Internal to the image topic: exact median and the Huber M-estimate of location of a series of
// float values held as runs of one array (region_statistics: the used pixels of a plane, row by
// row). Formulas in docs/image-regions.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace roughscope::image {

// values[start .. start + length) of the series' array.
struct ValueRun {
    std::uint32_t start = 0;
    std::uint32_t length = 0;
};

// The values of `values` in the runs, in run order; count = Σ lengths.
struct ValueSeries {
    const float* values = nullptr;
    std::span<const ValueRun> runs;
    std::size_t count = 0;
};

// Calls f(const float* first, std::size_t length) for each run.
template <class F>
void for_each_span(const ValueSeries& series, F&& f) {
    for (const ValueRun& r : series.runs) f(series.values + r.start, std::size_t{r.length});
}

// The median of the series (count > 0), exactly the value std::nth_element selects: the middle
// value for an odd count, the mean (in double) of the two middle values for an even one. A radix
// selection on the order-preserving 32-bit key of each float (−0 and +0 are equal): a histogram
// of the high 16 bits, then one of the low 16 bits within the bucket that holds the middle; two
// reads of the series, no copy.
double series_median(const ValueSeries& series);

struct HuberLocation {
    double median = 0;  // of the values
    double scale = 0;  // S = 1.4826 · MAD, or √(π/2) · mean |v − median| when MAD = 0; 0: all equal
    double location = 0;  // μ: Σ ψ_c(vᵢ − μ) = 0, c = 1.345 S; the median when S = 0
    int evaluations = 0;  // reads of the series for μ (each gives Σ ψ_c and the inlier counts)
};

// The Huber M-estimate of location with the scale fixed beforehand (count > 0). μ from the median
// by Newton steps on the piecewise-linear Σ ψ_c(vᵢ − μ): μ ← μ + Σ ψ_c / #{|vᵢ − μ| ≤ c}. When the
// sets of low and high outliers are the same at two successive μ, Σ ψ_c is linear between them
// and the step was exact; it also stops when μ changes by ≤ 10⁻¹² S. A step that leaves the
// bracket of the root known so far, or finds no inlier, is replaced by the secant of the bracket
// (or the always safe step Σ ψ_c / n).
HuberLocation huber_location(const ValueSeries& series);

// The same for one contiguous array (n ≤ 2³² − 1).
double series_median(std::span<const float> values);
HuberLocation huber_location(std::span<const float> values);

}  // namespace roughscope::image
