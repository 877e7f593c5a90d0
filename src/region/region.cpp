#include "roughscope/region/region.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

// Shown in describe(): the first vertices of a polygon.
constexpr std::size_t kDescribedVertices = 8;

std::string num(double value) { return check::format_number(value); }

std::string size_text(std::size_t width, std::size_t height) {
    return concat(std::to_string(width), " x ", std::to_string(height));
}

void check_finite(const char* what, double value) {
    if (!std::isfinite(value))
        throw InvalidArgument(concat("region: ", what, " = ", num(value), " is not finite"));
}

void check_size(const char* what, double value) {
    check_finite(what, value);
    if (!(value > 0.0))
        throw InvalidArgument(
            concat("region: ", what, " = ", num(value), " px must be > 0 (a region of no size)"));
}

// The image area [0, width] × [0, height], with room for the rounding of x + width.
bool inside_area(double lo, double hi, std::size_t extent) {
    const double slack = 1e-9 * std::max(1.0, static_cast<double>(extent));
    return lo >= -slack && hi <= static_cast<double>(extent) + slack;
}

// The columns i whose centres i + ½ lie in [lo, hi) (half-open), clipped to [0, width).
std::pair<std::size_t, std::size_t> centre_columns_half_open(double lo, double hi,
                                                             std::size_t width) {
    // i + ½ ≥ lo  ⇔  i ≥ lo − ½;  i + ½ < hi  ⇔  i < hi − ½.
    const double first = std::max(0.0, std::ceil(lo - 0.5));
    const double end = std::min(static_cast<double>(width), std::ceil(hi - 0.5));
    if (!(end > first)) return {0, 0};
    return {static_cast<std::size_t>(first), static_cast<std::size_t>(end)};
}

// The columns i whose centres lie in [lo, hi] (closed), clipped to [0, width).
std::pair<std::size_t, std::size_t> centre_columns_closed(double lo, double hi, std::size_t width) {
    const double first = std::max(0.0, std::ceil(lo - 0.5));
    const double end = std::min(static_cast<double>(width), std::floor(hi - 0.5) + 1.0);
    if (!(end > first)) return {0, 0};
    return {static_cast<std::size_t>(first), static_cast<std::size_t>(end)};
}

// The shapes as spans of pixel centres within rows, in row order then x (emit(row, x0, x1) with
// x0 < x1; the spans of a row are disjoint and increasing).
template <class Emit>
void rectangle_spans(const RectangleRegion& r, std::size_t width, std::size_t height, Emit&& emit) {
    const auto [x0, x1] = centre_columns_half_open(r.x_px, r.x_px + r.width_px, width);
    const auto [y0, y1] = centre_columns_half_open(r.y_px, r.y_px + r.height_px, height);
    if (x1 <= x0) return;
    for (std::size_t y = y0; y < y1; ++y) emit(y, x0, x1);
}

template <class Emit>
void circle_spans(const CircleRegion& c, std::size_t width, std::size_t height, Emit&& emit) {
    const auto [y0, y1] =
        centre_columns_closed(c.centre_y_px - c.radius_px, c.centre_y_px + c.radius_px, height);
    const double r2 = c.radius_px * c.radius_px;
    for (std::size_t y = y0; y < y1; ++y) {
        const double dy = static_cast<double>(y) + 0.5 - c.centre_y_px;
        const double rest = r2 - dy * dy;
        if (rest < 0.0) continue;
        const double half = std::sqrt(rest);
        auto [x0, x1] = centre_columns_closed(c.centre_x_px - half, c.centre_x_px + half, width);
        // The square root may round the span by one ulp: decide the end pixels exactly.
        auto in = [&](std::size_t x) {
            const double dx = static_cast<double>(x) + 0.5 - c.centre_x_px;
            return dx * dx + dy * dy <= r2;
        };
        if (x0 > 0 && in(x0 - 1)) --x0;
        if (x1 < width && in(x1)) ++x1;
        while (x0 < x1 && !in(x0)) ++x0;
        while (x1 > x0 && !in(x1 - 1)) --x1;
        if (x0 < x1) emit(y, x0, x1);
    }
}

// Scan line through the row's pixel centres: the crossings of the outline (edges half-open in
// y), sorted; the centres in [x_2k, x_2k+1) are inside (even-odd rule).
template <class Emit>
void polygon_spans(const PolygonRegion& p, std::size_t width, std::size_t height, Emit&& emit) {
    const auto& v = p.vertices_px;
    std::vector<double> crossings;
    for (std::size_t y = 0; y < height; ++y) {
        const double yc = static_cast<double>(y) + 0.5;
        crossings.clear();
        for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
            const double yi = v[i][1], yj = v[j][1];
            if ((yi > yc) != (yj > yc))
                crossings.push_back(v[i][0] + (yc - yi) * (v[j][0] - v[i][0]) / (yj - yi));
        }
        std::sort(crossings.begin(), crossings.end());
        for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
            const auto [x0, x1] = centre_columns_half_open(crossings[k], crossings[k + 1], width);
            if (x0 < x1) emit(y, x0, x1);
        }
    }
}

// The runs of nonzero bytes of a row-major width × height mask (zero words skipped 8 at a time).
template <class Emit>
void mask_spans(const std::uint8_t* mask, std::size_t width, std::size_t height, Emit&& emit) {
    for (std::size_t y = 0; y < height; ++y) {
        const std::uint8_t* row = mask + y * width;
        std::size_t x = 0;
        while (x < width) {
            while (x + 8 <= width) {
                std::uint64_t word = 0;
                std::memcpy(&word, row + x, sizeof word);
                if (word != 0) break;
                x += 8;
            }
            while (x < width && row[x] == 0) ++x;
            if (x == width) break;
            const std::size_t start = x;
            while (x < width && row[x] != 0) ++x;
            emit(y, start, x);
        }
    }
}

}  // namespace

void check_region(const Region& region) {
    std::visit(
        [](const auto& r) {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, RectangleRegion>) {
                check_finite("rectangle x", r.x_px);
                check_finite("rectangle y", r.y_px);
                check_size("rectangle width", r.width_px);
                check_size("rectangle height", r.height_px);
            } else if constexpr (std::is_same_v<T, CircleRegion>) {
                check_finite("circle centre x", r.centre_x_px);
                check_finite("circle centre y", r.centre_y_px);
                check_size("circle radius", r.radius_px);
            } else if constexpr (std::is_same_v<T, PolygonRegion>) {
                if (r.vertices_px.size() < 3)
                    throw InvalidArgument(concat("region: polygon with ",
                                                 std::to_string(r.vertices_px.size()),
                                                 " vertices; a polygon needs at least 3"));
                for (std::size_t i = 0; i < r.vertices_px.size(); ++i)
                    for (const double c : r.vertices_px[i])
                        if (!std::isfinite(c))
                            throw InvalidArgument(concat("region: polygon vertex ",
                                                         std::to_string(i + 1), " has coordinate ",
                                                         num(c), ", not finite"));
            } else {
                static_assert(std::is_same_v<T, MaskRegion>, "unhandled region type");
                if (r.width == 0 || r.height == 0)
                    throw InvalidArgument(concat("region: mask of ", size_text(r.width, r.height),
                                                 " pixels; it must be at least 1 x 1"));
                if (r.inside.size() != r.width * r.height)
                    throw InvalidArgument(concat("region: mask of ", size_text(r.width, r.height),
                                                 " pixels holds ", std::to_string(r.inside.size()),
                                                 " values, not ",
                                                 std::to_string(r.width * r.height)));
            }
        },
        region);
}

std::string describe(const Region& region) {
    return std::visit(
        [](const auto& r) -> std::string {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, RectangleRegion>) {
                return concat("rect [", num(r.x_px), ", ", num(r.y_px), ", ", num(r.width_px), ", ",
                              num(r.height_px), "]");
            } else if constexpr (std::is_same_v<T, CircleRegion>) {
                return concat("circle [", num(r.centre_x_px), ", ", num(r.centre_y_px), ", ",
                              num(r.radius_px), "]");
            } else if constexpr (std::is_same_v<T, PolygonRegion>) {
                std::vector<std::string> points;
                const std::size_t shown = std::min(r.vertices_px.size(), kDescribedVertices);
                for (std::size_t i = 0; i < shown; ++i)
                    points.push_back(
                        concat("(", num(r.vertices_px[i][0]), ", ", num(r.vertices_px[i][1]), ")"));
                if (shown < r.vertices_px.size())
                    points.push_back(
                        concat("... (", std::to_string(r.vertices_px.size()), " vertices)"));
                return concat("polygon [", join(points, ", "), "]");
            } else {
                static_assert(std::is_same_v<T, MaskRegion>, "unhandled region type");
                const auto in = std::count_if(r.inside.begin(), r.inside.end(),
                                              [](std::uint8_t b) { return b != 0; });
                return concat("mask [", size_text(r.width, r.height), ", ", std::to_string(in),
                              " pixels in]");
            }
        },
        region);
}

RegionSpans region_spans(const Region& region, std::size_t width, std::size_t height) {
    check_region(region);
    if (width == 0 || height == 0)
        throw InvalidArgument(concat("region ", describe(region), ": image of ",
                                     size_text(width, height), " pixels has no pixel"));
    const auto outside = [&]() {
        return InvalidArgument(
            concat("region ", describe(region), " reaches outside the image of ",
                   size_text(width, height), " pixels (valid coordinates: x in [0, ",
                   std::to_string(width), "], y in [0, ", std::to_string(height), "])"));
    };
    RegionSpans out;
    out.width = width;
    out.height = height;
    const auto emit = [&](std::size_t y, std::size_t x0, std::size_t x1) {
        out.spans.push_back({static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(x0),
                             static_cast<std::uint32_t>(x1)});
        out.pixel_count += x1 - x0;
    };
    std::visit(
        [&](const auto& r) {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, RectangleRegion>) {
                if (!inside_area(r.x_px, r.x_px + r.width_px, width) ||
                    !inside_area(r.y_px, r.y_px + r.height_px, height))
                    throw outside();
                rectangle_spans(r, width, height, emit);
            } else if constexpr (std::is_same_v<T, CircleRegion>) {
                if (!inside_area(r.centre_x_px - r.radius_px, r.centre_x_px + r.radius_px, width) ||
                    !inside_area(r.centre_y_px - r.radius_px, r.centre_y_px + r.radius_px, height))
                    throw outside();
                circle_spans(r, width, height, emit);
            } else if constexpr (std::is_same_v<T, PolygonRegion>) {
                for (const auto& vertex : r.vertices_px)
                    if (!inside_area(vertex[0], vertex[0], width) ||
                        !inside_area(vertex[1], vertex[1], height))
                        throw outside();
                polygon_spans(r, width, height, emit);
            } else {
                static_assert(std::is_same_v<T, MaskRegion>, "unhandled region type");
                if (r.width != width || r.height != height)
                    throw InvalidArgument(concat("region: mask of ", size_text(r.width, r.height),
                                                 " pixels for an image of ",
                                                 size_text(width, height),
                                                 " pixels; the sizes must be equal"));
                mask_spans(r.inside.data(), width, height, emit);
            }
        },
        region);
    if (out.pixel_count == 0)
        throw InvalidArgument(concat("region ", describe(region), " holds no pixel centre of the ",
                                     size_text(width, height),
                                     " image (pixel (i, j) has its centre at (i + 0.5, j + 0.5))"));
    return out;
}

RegionSpans region_spans(const std::vector<std::uint8_t>& mask, std::size_t width,
                         std::size_t height) {
    if (mask.size() != width * height)
        throw InvalidArgument(concat("region mask of ", std::to_string(mask.size()),
                                     " pixels for an image of ", size_text(width, height), " = ",
                                     std::to_string(width * height),
                                     " pixels; the sizes must be equal"));
    RegionSpans out;
    out.width = width;
    out.height = height;
    mask_spans(mask.data(), width, height, [&](std::size_t y, std::size_t x0, std::size_t x1) {
        out.spans.push_back({static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(x0),
                             static_cast<std::uint32_t>(x1)});
        out.pixel_count += x1 - x0;
    });
    return out;
}

std::vector<std::uint8_t> rasterize(const RegionSpans& spans) {
    std::vector<std::uint8_t> mask;
    assign_large(mask, spans.width * spans.height, std::uint8_t{0});
    for (const PixelSpan& s : spans.spans) {
        const std::size_t row = std::size_t{s.row} * spans.width;
        std::fill(mask.begin() + static_cast<std::ptrdiff_t>(row + s.x_begin),
                  mask.begin() + static_cast<std::ptrdiff_t>(row + s.x_end), std::uint8_t{1});
    }
    return mask;
}

std::vector<std::uint8_t> rasterize(const Region& region, std::size_t width, std::size_t height) {
    return rasterize(region_spans(region, width, height));
}

MaskRegion mask_region_from_image(const LinearImage& mask_image) {
    check_linear_image(mask_image);
    MaskRegion mask;
    mask.width = mask_image.width;
    mask.height = mask_image.height;
    assign_large(mask.inside, mask_image.pixel_count(), std::uint8_t{0});
    const float* values = mask_image.plane(0);
    for (std::size_t k = 0; k < mask.inside.size(); ++k) mask.inside[k] = values[k] > 0.5F ? 1 : 0;
    return mask;
}

}  // namespace roughscope::image
