// A lamp and a camera at a finite distance from a flat sample (docs/measure.md "A lamp and a
// camera at a finite distance"): every pixel of the region sees its own geometry, and a point
// lamp's irradiance falls as 1/r². The paper's estimators (Eq. 17/19, the two-geometry solver,
// T given σ) assume one geometry for the whole region (a collimated light, an orthographic
// camera); with positions, the region's mean brightness is compared with the model's region
// mean at each pixel's own geometry instead.
//
// Frame: the sample frame of the capture file's light and view directions — the sample's plane
// z = 0, its normal +z, lengths in mm. Pixel (u, v) (column, row; row 0 at the top, image y
// down) has its centre at the plane point
//   X = ((u + ½ − u0) · sx, −(v + ½ − v0) · sy, 0)
// with (sx, sy) the sample plane's pixel size and (u0, v0) its origin in pixels (default the
// image centre, (W/2, H/2)). The mapping is affine: a camera that looks along the normal, or an
// image rectified to the sample's plane.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {

// Pixel sizes accepted on the sample's plane (mm): a nanometre to a kilometre.
inline constexpr double kMinPixelSizeMm = 1e-6;
inline constexpr double kMaxPixelSizeMm = 1e6;

// The region's model mean is taken over at most this many of its pixels (a uniform subsample in
// scan order; the model is smooth in X, so a 24-MP region costs what a small one does).
inline constexpr std::size_t kFiniteDistanceSamplePoints = 4096;

// The capture file's "sample_plane": how pixels map to the sample's plane (mm).
struct SamplePlane {
    std::array<double, 2> pixel_size_mm{1.0, 1.0};   // (sx, sy), each in [kMin, kMax]PixelSizeMm
    std::optional<std::array<double, 2>> origin_px;  // (u0, v0); default (W/2, H/2)
};

// The plane point (mm, z = 0) of the centre of pixel (column, row) of a width × height image.
// Throws InvalidArgument for a pixel size outside [kMinPixelSizeMm, kMaxPixelSizeMm] or a
// non-finite origin.
Eigen::Vector3d plane_point_mm(const SamplePlane& plane, std::size_t width, std::size_t height,
                               double column, double row);

// What a capture with a lamp or camera position measured (CaptureMeasurement::finite_distance).
// The capture's nominal geometry (CaptureSpec::geometry: the closed forms, the text output, the
// budget) is the geometry at the region's centroid X0.
struct FiniteDistance {
    Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();  // X0
    std::optional<double> lamp_distance_mm;                 // |P − X0| (a lamp position)
    std::optional<double> camera_distance_mm;               // |C − X0| (a camera position)
    // The spread of the geometry over the region (degrees, over the subsample).
    double theta_i_min_deg = 0.0, theta_i_max_deg = 0.0;
    double theta_s_min_deg = 0.0, theta_s_max_deg = 0.0;
    // The correction factor f = mean_X[B(geom(X)) · (r0/r(X))²] / B(geom(X0)) (dimensionless,
    // r = |P − X|, r0 = |P − X0|; no 1/r² for a collimated light) of the model B each estimate
    // was solved with, at its solution: σ/T of either correlation (very rough, Eq. 4/5) and T
    // given σ (the regime used). Unset when that estimate was not made.
    std::optional<double> correction_gaussian;
    std::optional<double> correction_exponential;
    std::optional<double> correction_T;
    // The subsample: each point's geometry and its weight (r0/r)² (not serialised).
    std::vector<Geometry> point_geometry;
    std::vector<double> point_weight;
};

}  // namespace roughscope::image
