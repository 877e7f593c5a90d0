// Regions of an image: the pixels a measurement averages over (paper §4.1, §5.1: brightness
// "averaged over a neighbourhood so that the effects of rough surface texture are smoothed away").
//
// Pixel coordinates (docs/image-regions.md): x to the right, y down, in pixels, with the origin at
// the top-left corner of the image. Pixel (column i, row j) covers [i, i + 1) × [j, j + 1); its
// centre is (i + ½, j + ½). The image covers [0, width] × [0, height]. A pixel belongs to a region
// when its centre is inside the shape, so a rectangle with integer corners holds exactly the
// pixels it covers, and a circle centred on pixel (i, j) has its centre at (i + ½, j + ½).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "roughscope/photo/image.hpp"

namespace roughscope::image {

// Top-left corner (x_px, y_px) and size. Pixel centre (cx, cy) is inside when
// x_px ≤ cx < x_px + width_px and y_px ≤ cy < y_px + height_px (half-open, so that adjacent
// rectangles share no pixel); {i, j, w, h} with integers holds columns i..i+w−1, rows j..j+h−1.
struct RectangleRegion {
    double x_px, y_px, width_px, height_px;
};

// Pixel centre (cx, cy) is inside when (cx − centre_x_px)² + (cy − centre_y_px)² ≤ radius_px².
struct CircleRegion {
    double centre_x_px, centre_y_px, radius_px;
};

// A closed polygon (the last vertex joins the first), ≥ 3 vertices, may self-intersect. Pixel
// centres inside by the even-odd rule (a ray from the centre to +x crosses the outline an odd
// number of times), with edges half-open in y, so that polygons sharing an edge share no pixel.
struct PolygonRegion {
    std::vector<std::array<double, 2>> vertices_px;
};

// One byte per pixel of an image of width × height, row-major: nonzero = inside.
struct MaskRegion {
    std::size_t width = 0, height = 0;
    std::vector<std::uint8_t> inside;
};

using Region = std::variant<RectangleRegion, CircleRegion, PolygonRegion, MaskRegion>;

// Throws InvalidArgument unless the region is well formed on its own: every coordinate finite,
// width, height and radius > 0, a polygon with ≥ 3 vertices, a mask of ≥ 1 × 1 pixels with
// width · height bytes.
void check_region(const Region& region);

// The region for messages and JSON, numbers in shortest round-trip form:
// "rect [x, y, w, h]", "circle [cx, cy, r]", "polygon [(x1, y1), (x2, y2), ...]" (the first 8
// vertices, then "... (N vertices)"), "mask [W x H, N pixels in]".
std::string describe(const Region& region);

// The region on the pixels of a width × height image: one byte per pixel, row-major, 1 when the
// pixel's centre is inside, else 0. Throws InvalidArgument (check_region) for a malformed region,
// when the shape reaches outside the image area [0, width] × [0, height] (the message gives the
// region and the image size), when it holds no pixel centre, and for a mask whose size is not
// the image's.
std::vector<std::uint8_t> rasterize(const Region& region, std::size_t width, std::size_t height);

// The same pixels as spans within rows, without a byte per pixel: the region of a 24-MP image is
// a few thousand spans (a rectangle: one per row) instead of 24 MB.
struct PixelSpan {
    std::uint32_t row = 0;
    std::uint32_t x_begin = 0, x_end = 0;  // columns [x_begin, x_end), x_begin < x_end
};
struct RegionSpans {
    std::size_t width = 0, height = 0;  // of the image
    std::vector<PixelSpan> spans;       // by row, then x; disjoint
    std::size_t pixel_count = 0;        // Σ (x_end − x_begin)
};

// rasterize()'s pixels as spans, with rasterize()'s checks and errors.
RegionSpans region_spans(const Region& region, std::size_t width, std::size_t height);
// The spans of a mask (nonzero bytes) of a width × height image; InvalidArgument when its size is
// not width · height. An all-zero mask gives no span.
RegionSpans region_spans(const std::vector<std::uint8_t>& mask, std::size_t width,
                         std::size_t height);
// The mask of the spans (1 inside, 0 outside).
std::vector<std::uint8_t> rasterize(const RegionSpans& spans);

// A mask from an image (e.g. one painted in an editor): pixel inside where the value of channel 0
// is > 0.5 (on the linear scale, 1 = full scale). Throws InvalidArgument for an inconsistent
// image (check_linear_image).
MaskRegion mask_region_from_image(const LinearImage& mask_image);

}  // namespace roughscope::image
