// The light's direction from a mirror sphere's highlight (objects/mirror_sphere.hpp). Formulas,
// frame and uncertainty model in docs/calibration.md.
#include "roughscope/objects/mirror_sphere.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "object_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

// The highlight must stand above the disc's median b by this many robust standard deviations of
// the disc (1.4826 · MAD) and by this fraction of b.
constexpr double kMinContrastSigmas = 8.0;
constexpr double kMinContrastFraction = 0.25;
// A highlight covering more than this fraction of the disc is not compact (a warning).
constexpr double kLargeHighlightFraction = 0.05;
// The step of the finite differences of the uncertainty, px.
constexpr double kDifferenceStepPx = 1e-3;

// One pixel whose centre lies inside the circle (and on the mask).
struct DiscPixel {
    std::size_t col = 0, row = 0;
    float value = 0.0f;  // channel average
    bool saturated = false;
};

// The pixels of the disc, in raster order, and the box of rows/columns they lie in.
struct Disc {
    std::vector<DiscPixel> pixels;
    std::size_t col0 = 0, row0 = 0, cols = 0, rows = 0;
};

// One 8-connected blob of pixels above the threshold (indices into Disc::pixels).
struct Blob {
    std::vector<std::size_t> members;
    double weight = 0.0;  // Σ (v − threshold)
};

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

// InvalidArgument unless the circle is finite, r ≥ kMirrorSphereMinRadiusPx and the disc lies
// inside the image.
void check_circle_in_image(const CircleFit& c, const LinearImage& image) {
    check::finite("mirror sphere circle centre x", c.centre_x_px);
    check::finite("mirror sphere circle centre y", c.centre_y_px);
    check::finite("mirror sphere circle radius", c.radius_px);
    if (!(c.radius_px >= kMirrorSphereMinRadiusPx))
        throw InvalidArgument(concat("mirror sphere circle radius = ", format_number(c.radius_px),
                                     " px is outside the valid range [",
                                     format_number(kMirrorSphereMinRadiusPx), ", inf) px"));
    const auto check_axis = [&](const char* axis, double centre, std::size_t size) {
        const double lo = c.radius_px, hi = static_cast<double>(size) - c.radius_px;
        if (!(centre >= lo && centre <= hi))
            throw InvalidArgument(
                concat("mirror sphere circle centre ", axis, " = ", format_number(centre),
                       " px (r = ", format_number(c.radius_px), " px) is outside the valid range [",
                       format_number(lo), ", ", format_number(hi),
                       "] px: the circle must lie inside the ", std::to_string(image.width), " x ",
                       std::to_string(image.height), " image ", image_name(image)));
    };
    check_axis("x", c.centre_x_px, image.width);
    check_axis("y", c.centre_y_px, image.height);
}

// InvalidArgument unless the input uncertainties are at most the radius (beyond it the circle is
// not known at all, and the propagated angle would overflow).
void check_uncertainties_within_radius(const MirrorSphereOptions& o, double radius_px) {
    const auto check_one = [&](const char* name, double value) {
        if (value > radius_px)
            throw InvalidArgument(concat("mirror sphere ", name, " = ", format_number(value),
                                         " px is outside the valid range [0, ",
                                         format_number(radius_px), "] px (at most the radius)"));
    };
    check_one("circle_uncertainty_px", o.circle_uncertainty_px);
    check_one("centroid_floor_px", o.centroid_floor_px);
}

// The pixels whose centre lies inside the circle (and on the mask; none without a value).
Disc disc_pixels(const LinearImage& image, const CircleFit& c, const std::uint8_t* mask) {
    Disc disc;
    const double r = c.radius_px;
    const auto first = [](double v) { return static_cast<std::size_t>(std::max(0.0, v - 0.5)); };
    disc.col0 = first(c.centre_x_px - r);
    disc.row0 = first(c.centre_y_px - r);
    const std::size_t col1 = std::min(image.width, first(c.centre_x_px + r) + 1);
    const std::size_t row1 = std::min(image.height, first(c.centre_y_px + r) + 1);
    disc.cols = col1 - disc.col0;
    disc.rows = row1 - disc.row0;
    const float scale = 1.0f / static_cast<float>(image.channels);
    for (std::size_t row = disc.row0; row < row1; ++row)
        for (std::size_t col = disc.col0; col < col1; ++col) {
            const double dx = static_cast<double>(col) + 0.5 - c.centre_x_px;
            const double dy = static_cast<double>(row) + 0.5 - c.centre_y_px;
            const std::size_t k = row * image.width + col;
            if (dx * dx + dy * dy >= r * r || (mask && !mask[k]) ||
                (image.flags[k] & kPixelMissing))
                continue;
            float v = 0.0f;
            for (std::size_t ch = 0; ch < image.channels; ++ch) v += image.value(ch, row, col);
            disc.pixels.push_back({col, row, v * scale, (image.flags[k] & kPixelSaturated) != 0});
        }
    return disc;
}

// The median and the robust standard deviation (1.4826 · MAD) of the disc's values.
std::pair<double, double> median_and_robust_sigma(const Disc& disc) {
    std::vector<float> v(disc.pixels.size());
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = disc.pixels[i].value;
    const auto median = [](std::vector<float>& x) {
        auto mid = x.begin() + static_cast<std::ptrdiff_t>(x.size() / 2);
        std::nth_element(x.begin(), mid, x.end());
        return static_cast<double>(*mid);
    };
    const double m = median(v);
    for (float& x : v) x = static_cast<float>(std::abs(x - m));
    return {m, 1.4826 * median(v)};
}

// The 8-connected groups of the disc's pixels above `threshold`.
std::vector<Blob> blobs_above(const Disc& disc, double threshold) {
    // Grid of the box: index + 1 of the disc pixel above the threshold, 0 elsewhere.
    std::vector<std::size_t> grid(disc.cols * disc.rows, 0);
    for (std::size_t i = 0; i < disc.pixels.size(); ++i)
        if (disc.pixels[i].value > threshold)
            grid[(disc.pixels[i].row - disc.row0) * disc.cols + disc.pixels[i].col - disc.col0] =
                i + 1;
    std::vector<Blob> blobs;
    std::deque<std::size_t> queue;
    for (std::size_t start = 0; start < grid.size(); ++start) {
        if (!grid[start]) continue;
        Blob blob;
        queue.push_back(start);
        const std::size_t seed = grid[start] - 1;
        grid[start] = 0;
        blob.members.push_back(seed);
        while (!queue.empty()) {
            const std::size_t g = queue.front();
            queue.pop_front();
            const std::size_t gr = g / disc.cols, gc = g % disc.cols;
            for (std::size_t nr = gr ? gr - 1 : 0; nr <= std::min(gr + 1, disc.rows - 1); ++nr)
                for (std::size_t nc = gc ? gc - 1 : 0; nc <= std::min(gc + 1, disc.cols - 1);
                     ++nc) {
                    const std::size_t n = nr * disc.cols + nc;
                    if (!grid[n]) continue;
                    blob.members.push_back(grid[n] - 1);
                    grid[n] = 0;
                    queue.push_back(n);
                }
        }
        for (const std::size_t i : blob.members) blob.weight += disc.pixels[i].value - threshold;
        blobs.push_back(std::move(blob));
    }
    std::sort(blobs.begin(), blobs.end(),
              [](const Blob& a, const Blob& b) { return a.weight > b.weight; });
    return blobs;
}

// The robust standard deviation of one pixel's noise: 1.4826 · MAD of the differences between
// horizontally neighbouring disc pixels outside the highlight, / √2 (smooth shading cancels).
double pixel_noise_sigma(const Disc& disc, double threshold) {
    std::vector<double> d;
    for (std::size_t i = 1; i < disc.pixels.size(); ++i) {
        const DiscPixel &a = disc.pixels[i - 1], &b = disc.pixels[i];
        if (a.row == b.row && a.col + 1 == b.col && a.value <= threshold && b.value <= threshold)
            d.push_back(std::abs(static_cast<double>(b.value) - a.value));
    }
    if (d.empty()) return 0.0;
    auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
    std::nth_element(d.begin(), mid, d.end());
    return 1.4826 * *mid / std::sqrt(2.0);
}

// The highlight's centroid: the weighted mean reflected direction (weights v − threshold) and the
// standard uncertainty of the pixel-space centroid per axis from the pixel noise,
// √(Σ (x_i − x̄)² s² / (Σ w)² + floor²).
struct Centroid {
    Eigen::Vector3d direction;
    double uncertainty_x_px = 0.0, uncertainty_y_px = 0.0;
};

Centroid highlight_centroid(const Disc& disc, const Blob& blob, double threshold,
                            double noise_sigma, const CircleFit& circle,
                            const MirrorSphereOptions& options) {
    Eigen::Vector3d sum_r = Eigen::Vector3d::Zero();
    double sw = 0, sx = 0, sy = 0;
    for (const std::size_t i : blob.members) {
        const DiscPixel& p = disc.pixels[i];
        const double x = static_cast<double>(p.col) + 0.5, y = static_cast<double>(p.row) + 0.5;
        const double w = p.value - threshold;
        sum_r += w * reflect_view(mirror_sphere_normal(x, y, circle), options.view);
        sw += w;
        sx += w * x;
        sy += w * y;
    }
    const double mx = sx / sw, my = sy / sw;
    double vx = 0, vy = 0;
    for (const std::size_t i : blob.members) {
        const DiscPixel& p = disc.pixels[i];
        const double dx = static_cast<double>(p.col) + 0.5 - mx;
        const double dy = static_cast<double>(p.row) + 0.5 - my;
        vx += dx * dx;
        vy += dy * dy;
    }
    const double s2 = noise_sigma * noise_sigma / (sw * sw);
    const double floor2 = options.centroid_floor_px * options.centroid_floor_px;
    return {sum_r.normalized(), std::sqrt(vx * s2 + floor2), std::sqrt(vy * s2 + floor2)};
}

// The angle between two unit vectors, radians (accurate also for small angles).
double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b));
}

// The standard uncertainty of L's direction, degrees: the RMS angle
// √(Σ_p (∂L/∂p · u_p)²) over p = the highlight's x and y and the circle's cx, cy and r, each
// derivative by central differences of L = reflect_view(n(x, y; circle), V).
double light_uncertainty_deg(double hx, double hy, const CircleFit& circle,
                             const Centroid& centroid, const MirrorSphereOptions& options) {
    const auto light_at = [&](double x, double y, const CircleFit& c) {
        return reflect_view(mirror_sphere_normal(x, y, c), options.view);
    };
    const double h = kDifferenceStepPx;
    double variance = 0.0;
    const auto add = [&](const Eigen::Vector3d& plus, const Eigen::Vector3d& minus, double u) {
        const double per_px = angle_between(plus, minus) / (2.0 * h);
        variance += per_px * per_px * u * u;
    };
    add(light_at(hx + h, hy, circle), light_at(hx - h, hy, circle), centroid.uncertainty_x_px);
    add(light_at(hx, hy + h, circle), light_at(hx, hy - h, circle), centroid.uncertainty_y_px);
    const double uc = options.circle_uncertainty_px;
    if (uc > 0.0) {
        CircleFit plus = circle, minus = circle;
        plus.centre_x_px += h;
        minus.centre_x_px -= h;
        add(light_at(hx, hy, plus), light_at(hx, hy, minus), uc);
        plus = minus = circle;
        plus.centre_y_px += h;
        minus.centre_y_px -= h;
        add(light_at(hx, hy, plus), light_at(hx, hy, minus), uc);
        plus = minus = circle;
        plus.radius_px += h;
        minus.radius_px -= h;
        add(light_at(hx, hy, plus), light_at(hx, hy, minus), uc);
    }
    return rad_to_deg(std::sqrt(variance));
}

// The warnings of a result: near the limb, several blobs, a large highlight.
void add_warnings(MirrorSphereLight& out, const std::vector<Blob>& blobs,
                  const MirrorSphereOptions& options) {
    if (out.highlight_rho > options.limb_warning_rho)
        out.warnings.push_back(concat(
            "the highlight is at ", format_number(std::round(out.highlight_rho * 1000) / 1000),
            " of the radius from the centre, near the limb, where the light's direction changes "
            "fast with the highlight's position and the circle (light ",
            format_number(std::round(out.theta_deg * 10) / 10), " deg from the camera axis)"));
    if (blobs.size() > 1)
        out.warnings.push_back(concat(
            std::to_string(blobs.size()), " separate bright blobs on the sphere; the brightest (",
            std::to_string(blobs[0].members.size()), " px) was used, the next has ",
            std::to_string(blobs[1].members.size()),
            " px (a second light, an interreflection, a scratch? restrict the search with a "
            "mask)"));
    if (static_cast<double>(out.highlight_pixels) >
        kLargeHighlightFraction * static_cast<double>(out.disc_pixels))
        out.warnings.push_back(concat(
            "the highlight covers ",
            format_number(std::round(1000.0 * static_cast<double>(out.highlight_pixels) /
                                     static_cast<double>(out.disc_pixels)) /
                          10),
            " % of the sphere: not a compact mirror highlight (a matte or rough sphere, a large "
            "source?)"));
}

}  // namespace

void check_mirror_sphere_options(const MirrorSphereOptions& options) {
    detail::check_unit_direction("mirror sphere view", options.view);
    if (!(options.threshold_fraction > 0.0 && options.threshold_fraction < 1.0))
        throw InvalidArgument(
            concat("mirror sphere threshold_fraction = ", format_number(options.threshold_fraction),
                   " is outside the valid range (0, 1)"));
    check::non_negative("mirror sphere circle_uncertainty_px", options.circle_uncertainty_px,
                        " px");
    check::non_negative("mirror sphere centroid_floor_px", options.centroid_floor_px, " px");
    if (!(options.limb_warning_rho > 0.0 && options.limb_warning_rho <= 1.0))
        throw InvalidArgument(
            concat("mirror sphere limb_warning_rho = ", format_number(options.limb_warning_rho),
                   " is outside the valid range (0, 1]"));
}

Eigen::Vector3d mirror_sphere_normal(double x_px, double y_px, const CircleFit& circle) {
    double nx = (x_px - circle.centre_x_px) / circle.radius_px;
    double ny = -(y_px - circle.centre_y_px) / circle.radius_px;  // image y down, frame y up
    const double rho2 = nx * nx + ny * ny;
    if (rho2 > 1.0) {
        const double s = 1.0 / std::sqrt(rho2);
        nx *= s;
        ny *= s;
    }
    return {nx, ny, std::sqrt(std::max(0.0, 1.0 - nx * nx - ny * ny))};
}

// The law of reflection: the angle of incidence equals the angle of reflection, in the plane of
// the normal, so the mirror sends light from L into V exactly when n bisects them, L = 2(n·V)n − V.
Eigen::Vector3d reflect_view(const Eigen::Vector3d& normal, const Eigen::Vector3d& view) {
    return 2.0 * normal.dot(view) * normal - view;
}

double polar_angle_deg(const Eigen::Vector3d& direction) {
    return rad_to_deg(std::atan2(direction.head<2>().norm(), direction.z()));
}

double azimuth_deg(const Eigen::Vector3d& direction) {
    return rad_to_deg(std::atan2(direction.y(), direction.x()));
}

CircleFit circle_from_mask(const std::vector<std::uint8_t>& mask, std::size_t width,
                           std::size_t height) {
    if (mask.size() != width * height)
        throw InvalidArgument(concat("sphere mask has ", std::to_string(mask.size()),
                                     " entries, the image ", std::to_string(width), " x ",
                                     std::to_string(height), " has ",
                                     std::to_string(width * height), " pixels"));
    double n = 0, sx = 0, sy = 0;
    for (std::size_t row = 0; row < height; ++row)
        for (std::size_t col = 0; col < width; ++col)
            if (mask[row * width + col]) {
                n += 1;
                sx += static_cast<double>(col) + 0.5;
                sy += static_cast<double>(row) + 0.5;
            }
    const double min_pixels = kPi * kMirrorSphereMinRadiusPx * kMirrorSphereMinRadiusPx;
    if (n < min_pixels)
        throw InvalidArgument(concat("sphere mask has ", format_number(n), " pixels; at least ",
                                     format_number(std::ceil(min_pixels)), " (a circle of radius ",
                                     format_number(kMirrorSphereMinRadiusPx), " px) are needed"));
    CircleFit c;
    c.centre_x_px = sx / n;
    c.centre_y_px = sy / n;
    c.radius_px = std::sqrt(n / kPi);
    return c;
}

MirrorSphereLight mirror_sphere_light(const LinearImage& image, const CircleFit& circle,
                                      const std::vector<std::uint8_t>* sphere_mask,
                                      const MirrorSphereOptions& options) {
    check_mirror_sphere_options(options);
    check_linear_image(image);
    if (sphere_mask && sphere_mask->size() != image.pixel_count())
        throw InvalidArgument(concat("sphere mask has ", std::to_string(sphere_mask->size()),
                                     " entries, the image ", image_name(image), " has ",
                                     std::to_string(image.pixel_count()), " pixels"));
    check_circle_in_image(circle, image);
    check_uncertainties_within_radius(options, circle.radius_px);
    MirrorSphereLight out;
    out.circle = circle;
    const Disc disc = disc_pixels(image, circle, sphere_mask ? sphere_mask->data() : nullptr);
    out.disc_pixels = disc.pixels.size();
    if (disc.pixels.empty())
        throw DataError(concat(image_name(image),
                               ": no pixel of the mask lies on the sphere's "
                               "circle; nothing to search"));
    const auto [background, sigma] = median_and_robust_sigma(disc);
    out.background = background;
    for (const DiscPixel& p : disc.pixels)
        out.peak = std::max(out.peak, static_cast<double>(p.value));
    const double need = std::max(kMinContrastSigmas * sigma, kMinContrastFraction * background);
    if (!(out.peak - background > need) || !(out.peak > background))
        throw DataError(
            concat(image_name(image), ": no highlight on the sphere: its brightest pixel ",
                   format_number(out.peak), " is not above the median ", format_number(background),
                   " by more than ", format_number(need),
                   " (8 robust standard deviations and 25 % of the median); is the circle on the "
                   "sphere, and the light reflected towards the camera?"));
    out.threshold = background + options.threshold_fraction * (out.peak - background);
    const std::vector<Blob> blobs = blobs_above(disc, out.threshold);
    const Blob& blob = blobs.front();
    out.blobs = blobs.size();
    out.highlight_pixels = blob.members.size();
    for (const std::size_t i : blob.members) out.saturated_pixels += disc.pixels[i].saturated;

    const Centroid centroid = highlight_centroid(
        disc, blob, out.threshold, pixel_noise_sigma(disc, out.threshold), circle, options);
    out.light = centroid.direction;
    out.theta_deg = polar_angle_deg(out.light);
    out.phi_deg = azimuth_deg(out.light);
    out.normal = (out.light + options.view).normalized();
    out.highlight_x_px = circle.centre_x_px + circle.radius_px * out.normal.x();
    out.highlight_y_px = circle.centre_y_px - circle.radius_px * out.normal.y();
    out.highlight_rho = out.normal.head<2>().norm();
    out.highlight_uncertainty_px =
        std::sqrt(0.5 * (centroid.uncertainty_x_px * centroid.uncertainty_x_px +
                         centroid.uncertainty_y_px * centroid.uncertainty_y_px));
    out.angle_uncertainty_deg =
        light_uncertainty_deg(out.highlight_x_px, out.highlight_y_px, circle, centroid, options);
    add_warnings(out, blobs, options);
    return out;
}

}  // namespace roughscope::image
