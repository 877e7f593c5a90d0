#include "roughscope/region/specular.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

constexpr double kMaxSmoothingSigmaPx = 100.0;
// Radii from the half width at half maximum w (docs/image-regions.md).
constexpr double kMinCoreRadiusPx = 1.5;
constexpr double kCorePerWidth = 0.25;
constexpr double kInnerPerWidth = 3.0;
constexpr double kOuterPerWidth = 4.0;
constexpr double kMinCoreToInnerPx = 2.0;
constexpr double kMinAnnulusWidthPx = 3.0;
// Surround level for the width: bins of the radial profile with at least this many pixels.
constexpr std::size_t kMinBinPixels = 3;
constexpr int kWidthIterations = 8;
// An annulus with fewer than this fraction of its full area inside the region gets a warning.
constexpr double kMinAnnulusFraction = 0.5;

std::string num(double value) { return check::format_number(value); }

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

std::string point_text(double x, double y) { return concat("(", num(x), ", ", num(y), ")"); }

struct Box {
    std::size_t x0, y0, x1, y1;  // half-open
};

// The per-pixel channel average, all pixels (flagged ones too: they still show where light is).
std::vector<float> channel_average(const LinearImage& image) {
    const std::size_t pixels = image.pixel_count();
    std::vector<float> average(image.plane(0), image.plane(0) + pixels);
    if (image.channels > 1) {
        for (std::size_t k = 0; k < pixels; ++k) {
            double sum = 0.0;
            for (std::size_t c = 0; c < image.channels; ++c) sum += image.plane(c)[k];
            average[k] = static_cast<float>(sum / static_cast<double>(image.channels));
        }
    }
    return average;
}

struct Peak {
    double x_px, y_px;
};

// The maximum of the smoothed average over the region, refined by a parabola through the
// maximum and its two neighbours along x and along y.
Peak find_peak(const LinearImage& image, const std::vector<float>& average,
               const std::vector<std::uint8_t>& mask, const Box& region, double sigma_px) {
    const std::size_t width = image.width, height = image.height;
    const auto margin = static_cast<std::size_t>(std::ceil(4.0 * sigma_px)) + 1;
    const Box crop{region.x0 > margin ? region.x0 - margin : 0,
                   region.y0 > margin ? region.y0 - margin : 0, std::min(width, region.x1 + margin),
                   std::min(height, region.y1 + margin)};
    cv::Mat source(static_cast<int>(crop.y1 - crop.y0), static_cast<int>(crop.x1 - crop.x0),
                   CV_32F);
    for (std::size_t y = crop.y0; y < crop.y1; ++y)
        for (std::size_t x = crop.x0; x < crop.x1; ++x)
            source.at<float>(static_cast<int>(y - crop.y0), static_cast<int>(x - crop.x0)) =
                average[y * width + x];
    cv::Mat smooth;
    if (sigma_px > 0.0)
        cv::GaussianBlur(source, smooth, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REFLECT);
    else
        smooth = source;
    const auto s = [&](std::size_t x, std::size_t y) {
        return static_cast<double>(
            smooth.at<float>(static_cast<int>(y - crop.y0), static_cast<int>(x - crop.x0)));
    };

    std::size_t best_x = region.x0, best_y = region.y0;
    double best = -HUGE_VAL;
    for (std::size_t y = region.y0; y < region.y1; ++y)
        for (std::size_t x = region.x0; x < region.x1; ++x)
            if (mask[y * width + x] != 0 && s(x, y) > best) {
                best = s(x, y);
                best_x = x;
                best_y = y;
            }
    const auto in_region = [&](std::size_t x, std::size_t y) { return mask[y * width + x] != 0; };
    if (best_x == 0 || best_y == 0 || best_x + 1 >= width || best_y + 1 >= height ||
        !in_region(best_x - 1, best_y) || !in_region(best_x + 1, best_y) ||
        !in_region(best_x, best_y - 1) || !in_region(best_x, best_y + 1))
        throw InvalidArgument(
            concat(image_name(image), ": the brightest point of the region, pixel ",
                   point_text(static_cast<double>(best_x), static_cast<double>(best_y)),
                   ", lies on the border of the region or the image: the highlight is not inside "
                   "the region (give a region around the whole highlight, or centre_px)"));
    const auto vertex = [](double minus, double centre, double plus) {
        const double curvature = minus - 2.0 * centre + plus;
        if (!(curvature < 0.0)) return 0.0;
        return std::clamp(0.5 * (minus - plus) / curvature, -0.5, 0.5);
    };
    const double dx = vertex(s(best_x - 1, best_y), best, s(best_x + 1, best_y));
    const double dy = vertex(s(best_x, best_y - 1), best, s(best_x, best_y + 1));
    return {static_cast<double>(best_x) + 0.5 + dx, static_cast<double>(best_y) + 0.5 + dy};
}

// Radial profile of the (unsmoothed) average over the region: bin k holds the pixels whose
// centres lie at distance d ∈ [k, k + 1) from the centre.
struct Profile {
    std::vector<double> mean_value, mean_radius;
    std::vector<std::size_t> count;
};

Profile radial_profile(const LinearImage& image, const std::vector<float>& average,
                       const std::vector<std::uint8_t>& mask, const Box& region, double cx,
                       double cy) {
    Profile p;
    for (std::size_t y = region.y0; y < region.y1; ++y)
        for (std::size_t x = region.x0; x < region.x1; ++x) {
            const std::size_t k = y * image.width + x;
            if (mask[k] == 0) continue;
            const double d =
                std::hypot(static_cast<double>(x) + 0.5 - cx, static_cast<double>(y) + 0.5 - cy);
            const auto bin = static_cast<std::size_t>(d);
            if (bin >= p.count.size()) {
                p.count.resize(bin + 1, 0);
                p.mean_value.resize(bin + 1, 0.0);
                p.mean_radius.resize(bin + 1, 0.0);
            }
            ++p.count[bin];
            p.mean_value[bin] += average[k];
            p.mean_radius[bin] += d;
        }
    for (std::size_t b = 0; b < p.count.size(); ++b)
        if (p.count[b] > 0) {
            p.mean_value[b] /= static_cast<double>(p.count[b]);
            p.mean_radius[b] /= static_cast<double>(p.count[b]);
        }
    return p;
}

// The radius where the profile first falls to half-way between `peak` and `surround`,
// interpolated between the two bins around it with ln(v − surround) linear in r² (exact for a
// Gaussian lobe; linear in r when a value is not above the surround); nullopt when it never does.
std::optional<double> half_crossing(const Profile& p, std::size_t first, double peak,
                                    double surround) {
    const double half = 0.5 * (peak + surround);
    std::size_t previous = first;
    for (std::size_t b = first + 1; b < p.count.size(); ++b) {
        if (p.count[b] == 0) continue;
        if (p.mean_value[b] <= half) {
            const double v0 = p.mean_value[previous], v1 = p.mean_value[b];
            const double r0 = p.mean_radius[previous], r1 = p.mean_radius[b];
            if (v1 > surround && v0 > v1) {
                const double l0 = std::log(v0 - surround), l1 = std::log(v1 - surround);
                const double lh = std::log(half - surround);
                return std::sqrt(r0 * r0 + (l0 - lh) / (l0 - l1) * (r1 * r1 - r0 * r0));
            }
            return r0 + (v0 - half) / (v0 - v1) * (r1 - r0);
        }
        previous = b;
    }
    return std::nullopt;
}

// The peak level: the first bin's value extrapolated to r = 0 with the second bin, linear in r²
// (v ≈ P (1 − r² / 2 s²) near the top of a lobe); never below the first bin's value.
double peak_level(const Profile& p, std::size_t first) {
    const double v0 = p.mean_value[first], r0 = p.mean_radius[first];
    for (std::size_t b = first + 1; b < p.count.size(); ++b) {
        if (p.count[b] == 0) continue;
        const double v1 = p.mean_value[b], r1 = p.mean_radius[b];
        if (!(r1 > r0)) break;
        return std::max(v0, v0 + (v0 - v1) * r0 * r0 / (r1 * r1 - r0 * r0));
    }
    return v0;
}

// Mean of the profile (pixel-weighted) over radii (lo, hi]; nullopt when no pixel is there.
std::optional<double> surround_level(const Profile& p, double lo, double hi) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t b = 0; b < p.count.size(); ++b)
        if (p.count[b] > 0 && p.mean_radius[b] > lo && p.mean_radius[b] <= hi) {
            sum += p.mean_value[b] * static_cast<double>(p.count[b]);
            n += p.count[b];
        }
    if (n == 0) return std::nullopt;
    return sum / static_cast<double>(n);
}

struct Width {
    double width_px;
    bool crossed;
};

// Half width at half maximum above the surround: peak from the first profile bins, surround first
// the lowest well-filled bin, then (iterated) the profile mean over (3 w, 4 w].
Width highlight_width(const LinearImage& image, const Profile& p, double cx, double cy) {
    std::size_t first = 0;
    while (first < p.count.size() && p.count[first] == 0) ++first;
    if (first == p.count.size())
        throw InvalidArgument(concat(image_name(image), ": the region holds no pixel"));
    const double peak = peak_level(p, first);
    double surround = HUGE_VAL;
    for (std::size_t b = first; b < p.count.size(); ++b)
        if (p.count[b] >= kMinBinPixels) surround = std::min(surround, p.mean_value[b]);
    if (!std::isfinite(surround)) surround = peak;
    if (!(peak > surround))
        throw InvalidArgument(concat(
            image_name(image), ": no highlight at ", point_text(cx, cy), ": the centre (",
            num(peak), ") is not brighter than the rest of the region (", num(surround), ")"));
    double w = 0.0;
    bool crossed = false;
    for (int iteration = 0; iteration < kWidthIterations; ++iteration) {
        const std::optional<double> crossing = half_crossing(p, first, peak, surround);
        crossed = crossing.has_value();
        const double next = crossing.value_or(p.mean_radius.back());
        const bool stable = std::abs(next - w) < 1e-3;
        w = next;
        if (stable || !crossed) break;
        const std::optional<double> level =
            surround_level(p, kInnerPerWidth * w, kOuterPerWidth * w);
        if (!level || !(peak > *level)) break;
        surround = *level;
    }
    return {w, crossed};
}

std::string prefixed(const char* what, const std::string& message) {
    return concat(what, ": ", message);
}

}  // namespace

void check_highlight_options(const HighlightOptions& options) {
    if (!(std::isfinite(options.smoothing_sigma_px) && options.smoothing_sigma_px >= 0.0 &&
          options.smoothing_sigma_px <= kMaxSmoothingSigmaPx))
        throw InvalidArgument(
            concat("highlight: smoothing_sigma_px = ", num(options.smoothing_sigma_px),
                   " must be in [0, ", num(kMaxSmoothingSigmaPx), "] px (0: no smoothing)"));
    const auto radius = [](const char* name, const std::optional<double>& r) {
        if (r && !(std::isfinite(*r) && *r > 0.0))
            throw InvalidArgument(
                concat("highlight: ", name, " = ", num(*r), " px must be finite and > 0"));
    };
    radius("core_radius_px", options.core_radius_px);
    radius("annulus_inner_px", options.annulus_inner_px);
    radius("annulus_outer_px", options.annulus_outer_px);
    if (options.core_radius_px && options.annulus_inner_px &&
        *options.core_radius_px > *options.annulus_inner_px)
        throw InvalidArgument(
            concat("highlight: core_radius_px = ", num(*options.core_radius_px),
                   " px must be ≤ annulus_inner_px = ", num(*options.annulus_inner_px), " px"));
    if (options.annulus_inner_px && options.annulus_outer_px &&
        !(*options.annulus_inner_px < *options.annulus_outer_px))
        throw InvalidArgument(
            concat("highlight: annulus_inner_px = ", num(*options.annulus_inner_px),
                   " px must be < annulus_outer_px = ", num(*options.annulus_outer_px), " px"));
    if (options.core_radius_px && options.annulus_outer_px && !options.annulus_inner_px &&
        !(*options.core_radius_px < *options.annulus_outer_px))
        throw InvalidArgument(
            concat("highlight: core_radius_px = ", num(*options.core_radius_px),
                   " px must be < annulus_outer_px = ", num(*options.annulus_outer_px), " px"));
    if (options.centre_px)
        for (const double c : *options.centre_px)
            if (!std::isfinite(c))
                throw InvalidArgument(
                    concat("highlight: centre_px coordinate ", num(c), " is not finite"));
    check_region_statistics_options(options.statistics);
}

HighlightMeasurement measure_highlight(const LinearImage& image,
                                       const std::vector<std::uint8_t>& region_mask,
                                       const HighlightOptions& options) {
    check_linear_image(image);
    check_highlight_options(options);
    const std::string name = image_name(image);
    const std::size_t width = image.width, height = image.height;
    if (region_mask.size() != image.pixel_count())
        throw InvalidArgument(concat(name, ": region mask of ", std::to_string(region_mask.size()),
                                     " pixels for an image of ", std::to_string(width), " x ",
                                     std::to_string(height), " pixels; the sizes must be equal"));
    Box region{width, height, 0, 0};
    for (std::size_t y = 0; y < height; ++y)
        for (std::size_t x = 0; x < width; ++x)
            if (region_mask[y * width + x] != 0) {
                region.x0 = std::min(region.x0, x);
                region.y0 = std::min(region.y0, y);
                region.x1 = std::max(region.x1, x + 1);
                region.y1 = std::max(region.y1, y + 1);
            }
    if (region.x1 == 0) throw InvalidArgument(concat(name, ": the highlight region is empty"));

    const std::vector<float> average = channel_average(image);
    HighlightMeasurement m;
    if (options.centre_px) {
        const auto [x, y] = *options.centre_px;
        if (x < 0.0 || y < 0.0 || x > static_cast<double>(width) || y > static_cast<double>(height))
            throw InvalidArgument(
                concat(name, ": highlight centre ", point_text(x, y), " lies outside the image of ",
                       std::to_string(width), " x ", std::to_string(height), " pixels (x in [0, ",
                       std::to_string(width), "], y in [0, ", std::to_string(height), "])"));
        m.centre_x_px = x;
        m.centre_y_px = y;
    } else {
        const Peak peak =
            find_peak(image, average, region_mask, region, options.smoothing_sigma_px);
        m.centre_x_px = peak.x_px;
        m.centre_y_px = peak.y_px;
    }
    const double cx = m.centre_x_px, cy = m.centre_y_px;

    const Profile profile = radial_profile(image, average, region_mask, region, cx, cy);
    const Width w = highlight_width(image, profile, cx, cy);
    m.width_px = w.width_px;
    if (!w.crossed)
        m.warnings.push_back(
            concat("the highlight does not fall to half its height inside the "
                   "region: width_px ",
                   num(w.width_px), " is the region's extent, a lower bound"));

    m.core_radius_px =
        options.core_radius_px.value_or(std::max(kMinCoreRadiusPx, kCorePerWidth * m.width_px));
    m.annulus_inner_px = options.annulus_inner_px.value_or(
        std::max(kInnerPerWidth * m.width_px, m.core_radius_px + kMinCoreToInnerPx));
    m.annulus_outer_px = options.annulus_outer_px.value_or(
        std::max(kOuterPerWidth * m.width_px, m.annulus_inner_px + kMinAnnulusWidthPx));
    if (m.core_radius_px > m.annulus_inner_px || !(m.annulus_inner_px < m.annulus_outer_px))
        throw InvalidArgument(
            concat(name, ": highlight radii core ", num(m.core_radius_px), ", annulus ",
                   num(m.annulus_inner_px), " to ", num(m.annulus_outer_px),
                   " px (given and chosen from the width ", num(m.width_px),
                   " px) must satisfy core ≤ annulus_inner < annulus_outer; give all three"));

    // Core d ≤ core, annulus inner < d ≤ outer, both inside the region.
    std::vector<std::uint8_t> core_mask(region_mask.size(), 0), annulus_mask(region_mask.size(), 0);
    std::size_t core_pixels = 0, annulus_pixels = 0;
    const double core2 = m.core_radius_px * m.core_radius_px;
    const double inner2 = m.annulus_inner_px * m.annulus_inner_px;
    const double outer2 = m.annulus_outer_px * m.annulus_outer_px;
    for (std::size_t y = region.y0; y < region.y1; ++y)
        for (std::size_t x = region.x0; x < region.x1; ++x) {
            const std::size_t k = y * width + x;
            if (region_mask[k] == 0) continue;
            const double dx = static_cast<double>(x) + 0.5 - cx;
            const double dy = static_cast<double>(y) + 0.5 - cy;
            const double d2 = dx * dx + dy * dy;
            if (d2 <= core2) {
                core_mask[k] = 1;
                ++core_pixels;
            } else if (d2 > inner2 && d2 <= outer2) {
                annulus_mask[k] = 1;
                ++annulus_pixels;
            }
        }
    const std::string core_text = concat("highlight core (radius ", num(m.core_radius_px),
                                         " px about ", point_text(cx, cy), ")");
    const std::string annulus_text =
        concat("highlight annulus (", num(m.annulus_inner_px), " to ", num(m.annulus_outer_px),
               " px about ", point_text(cx, cy), ")");
    if (core_pixels == 0)
        throw InvalidArgument(concat(name, ": ", core_text, " holds no pixel of the region"));
    if (annulus_pixels == 0)
        throw InvalidArgument(concat(name, ": ", annulus_text,
                                     " holds no pixel of the region; give a larger region or "
                                     "smaller annulus radii"));
    const double full_annulus = std::numbers::pi * (outer2 - inner2);
    if (static_cast<double>(annulus_pixels) < kMinAnnulusFraction * full_annulus)
        m.warnings.push_back(concat(annulus_text, ": only ", std::to_string(annulus_pixels),
                                    " of about ", std::to_string(std::lround(full_annulus)),
                                    " pixels lie in the region"));

    try {
        m.core = region_statistics(image, core_mask, options.statistics);
    } catch (const InvalidArgument& e) {
        throw InvalidArgument(prefixed(core_text.c_str(), e.what()));
    }
    try {
        m.annulus = region_statistics(image, annulus_mask, options.statistics);
    } catch (const InvalidArgument& e) {
        throw InvalidArgument(prefixed(annulus_text.c_str(), e.what()));
    }
    // The core is small by design: its "too few tiles" warning (the last one) is not passed on;
    // its pixel error already holds the lobe's own variation across it.
    const std::size_t core_warnings = m.core.warnings.size() - (m.core.average.tiles < 2 ? 1 : 0);
    for (std::size_t i = 0; i < core_warnings; ++i)
        m.warnings.push_back(concat("core: ", m.core.warnings[i]));
    for (const std::string& warning : m.annulus.warnings)
        m.warnings.push_back(concat("annulus: ", warning));
    if (m.core.pixels_saturated > 0)
        m.warnings.push_back(concat("core: ", std::to_string(m.core.pixels_saturated),
                                    " saturated pixel(s) left out, so E_tot is biased low; "
                                    "use a shorter exposure"));

    m.E_tot = m.core.average.mean;
    m.E_dif = m.annulus.average.mean;
    if (!(m.E_tot > 0.0) || !(m.E_dif > 0.0))
        throw InvalidArgument(concat(
            name, ": highlight means E_tot = ", num(m.E_tot), ", E_dif = ", num(m.E_dif),
            " must both be > 0 (a black core or surround: check the black level and exposure)"));
    const auto relative = [](const ChannelStatistics& s) {
        return std::max(s.stderr_pixel, s.stderr_tiles) / s.mean;
    };
    m.E_tot_relative_stderr = relative(m.core.average);
    m.E_dif_relative_stderr = relative(m.annulus.average);
    if (!(m.E_tot > m.E_dif))
        m.warnings.push_back(concat("E_tot = ", num(m.E_tot), " is not above E_dif = ",
                                    num(m.E_dif), ": no specular excess (R_spec ≤ 0)"));
    return m;
}

}  // namespace roughscope::image
