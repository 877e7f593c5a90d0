// The outline of a curved object in a photograph (paper §5.2): the bright connected region of a
// cylinder or a sphere against a darker background, its sub-pixel edge, and the circle (sphere)
// or the two straight edges (cylinder) that give the object's geometry. Formulas in
// docs/curved-objects.md.
//
// The silhouette is the lit outline: where the surface darkens to the background before its limb
// (light at the camera, a narrow very-rough lobe) the detected circle or edges are short of the
// object's — give them instead (docs/curved-objects.md).
//
// Image coordinates: x to the right, y down, pixel (col, row) has its centre at (col + ½, row + ½)
// (docs/image-regions.md). All lengths here are pixels (_px).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "roughscope/photo/image.hpp"

namespace roughscope::image {

struct SilhouetteOptions {
    // Level (linear scale, channel average) separating object from background. None: automatic,
    // every statistic from a regular subsample of about 2^18 pixels (every ⌊n/2^18⌋-th):
    // Otsu's threshold t_O on the channel average (OpenCV), then the edge level
    //   t = min(t_O, μ_b + max(6 s_b, edge_fraction · (μ_o − μ_b)))
    // with μ_b, s_b the median and 1.4826 · MAD of the pixels below t_O (robust to the object's
    // dark limb, which is below t_O too) and μ_o the mean of those above: low enough to follow a
    // limb that darkens towards the edge, high enough to stay out of the background noise.
    std::optional<double> threshold;
    double edge_fraction = 0.01;  // (0, 1)
    // The largest connected bright component must cover at least this fraction of the image.
    double min_object_fraction = 0.01;  // (0, 1)
};

// One sub-pixel edge point (image coordinates, px) and the outward normal of the outline there
// (unit; from the 3 × 3 Sobel gradient of the mask; (0, 0) for points given by the caller).
struct EdgePoint {
    double x_px = 0.0;
    double y_px = 0.0;
    double normal_x = 0.0;
    double normal_y = 0.0;
};

struct Silhouette {
    std::size_t width = 0, height = 0;
    std::vector<std::uint8_t> mask;        // width · height, 1 on the object (row-major)
    double threshold = 0.0;                // the level used (linear scale)
    std::optional<double> otsu_threshold;  // automatic only
    std::size_t pixel_count = 0;           // pixels of the object (holes filled)
    double centroid_x_px = 0.0, centroid_y_px = 0.0;  // mean pixel centre of the object
    // Bounding box of the object, half-open pixel ranges.
    std::size_t col_min = 0, col_max = 0, row_min = 0, row_max = 0;
    bool touches_left = false, touches_right = false, touches_top = false, touches_bottom = false;
    // Sub-pixel boundary points between an object pixel i and a background pixel o next to it,
    // along the row or column closest to the edge's normal: the midpoint of i and o (unbiased
    // for a sharp edge sampled at pixel centres, also where the limb darkens towards the edge);
    // where the object is flat up to the edge, the crossing of the level halfway between the
    // object's and the background's local values, interpolated between i and o (a blurred edge).
    // The circle and line fits average the points to well below a pixel. Points on the image border
    // (where the object is cut by the frame) are not edges and are not listed.
    std::vector<EdgePoint> boundary;
    bool touches_border() const {
        return touches_left || touches_right || touches_top || touches_bottom;
    }
};

// Finds the object: the largest 8-connected component above the level (cv::connectedComponents-
// WithStats on the mask reduced by f × f blocks, a block on when any of its pixels is,
// f = ⌊√(n / 2^18)⌋ — 1, the exact mask, below 2^20 pixels; the object is then its pixels above
// the level in that component's blocks), with the gaps along each row between its first and last
// pixel filled (dark texture, a flagged pixel: the objects here,
// cylinders and spheres seen whole, are convex along image rows). Throws InvalidArgument for an
// inconsistent image (check_linear_image) or bad options, DataError when no object is found
// (uniform image, component below min_object_fraction, no background pixel).
Silhouette find_silhouette(const LinearImage& image, const SilhouetteOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Circle (sphere)

struct CircleFit {
    double centre_x_px = 0.0;
    double centre_y_px = 0.0;
    double radius_px = 0.0;
    double rms_residual_px = 0.0;  // RMS of |p − c| − R over the points
    std::size_t points = 0;
};

// Least-squares circle: algebraic (Kåsa) fit, refined by Gauss–Newton on the geometric distances
// |p − c| − R. Throws InvalidArgument for fewer than 3 points or non-finite coordinates,
// DataError when the points are collinear (no circle).
CircleFit fit_circle(const std::vector<EdgePoint>& points);

struct CircleFitOptions {
    // The silhouette is not circular when the RMS residual exceeds
    // max(max_rms_px, max_rms_fraction · R).
    double max_rms_px = 0.75;
    double max_rms_fraction = 0.01;
};

// The circle of a sphere's silhouette. DataError when the object touches the image border (part
// of the outline is missing) or is not circular (the message gives the RMS residual and the
// limit).
CircleFit fit_sphere_circle(const Silhouette& silhouette, const CircleFitOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Cylinder axis

struct CylinderAxis {
    // A point of the axis and its unit direction, image coordinates (x right, y down).
    double point_x_px = 0.0, point_y_px = 0.0;
    double direction_x = 0.0, direction_y = 1.0;
    double radius_px = 0.0;
    bool detected = false;         // from the silhouette (else given)
    double rms_residual_px = 0.0;  // detected: RMS distance of the edge points from their lines
    std::size_t points = 0;        // detected: edge points used
    // The unit vector across the axis, in the image plane, towards the "right" half: the one with
    // a positive x component (for a horizontal axis: pointing up, −y).
    double across_x() const;
    double across_y() const;
    // Signed distance of an image point from the axis along across(), px.
    double across_distance_px(double x_px, double y_px) const;
};

// An axis from a point and a direction (any length, normalised; the sign does not matter) and
// the radius. InvalidArgument for a zero or non-finite direction or a radius not > 0.
CylinderAxis cylinder_axis_from_line(double point_x_px, double point_y_px, double direction_x,
                                     double direction_y, double radius_px);

// An axis from the two silhouette edges, each given by two points: the mid-line, radius = half
// the distance between the edges. InvalidArgument when a pair coincides, the edges are not
// parallel within 1°, or they coincide.
CylinderAxis cylinder_axis_from_edges(const EdgePoint& a0, const EdgePoint& a1, const EdgePoint& b0,
                                      const EdgePoint& b1);

struct CylinderAxisOptions {
    // Edge points farther than this from their line are dropped before the final fit (the ends
    // of a cylinder that ends inside the image); then the silhouette is not cylinder-like when
    // the RMS residual exceeds max(max_rms_px, max_rms_fraction · R) or the edges are not
    // parallel within max_angle_deg.
    double outlier_px = 3.0;
    double max_rms_px = 0.75;
    double max_rms_fraction = 0.01;
    double max_angle_deg = 1.0;
};

// The axis of a cylinder seen side-on: the edge orientation from the doubled-angle mean of the
// boundary normals, the boundary points split by the side of the object's centroid they lie on,
// a least-squares line through each
// side (with the outliers dropped), axis = the mid-line, radius = half the distance between the
// lines. Works for any orientation. DataError when an edge is missing (the object touches the
// image border along its side, or a side has too few points), the edges are not parallel, or the
// outline is not straight (the message gives the residual and the limit).
CylinderAxis fit_cylinder_axis(const Silhouette& silhouette,
                               const CylinderAxisOptions& options = {});

}  // namespace roughscope::image
