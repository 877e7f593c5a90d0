// The light's direction from a photograph of a mirror sphere (a ball bearing): the calibration
// step of a capture (issue 35). Formulas, frame and uncertainty model in docs/calibration.md.
//
// Camera frame as sphere.hpp (x image right, y image UP, z towards the camera; orthographic).
// Image coordinates: x right, y down, pixel (col, row) has its centre at (col + ½, row + ½)
// (docs/image-regions.md). On the circle (cx, cy, r) the point (x, y) has the normal
//   n = ((x − cx)/r, −(y − cy)/r, √(1 − ρ²)),   ρ² = ((x − cx)² + (y − cy)²)/r²,
// and a mirror there reflects the view direction V into R = 2(n·V)n − V: the highlight is where
// R is the light's direction L.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "roughscope/objects/silhouette.hpp"
#include "roughscope/photo/image.hpp"

namespace roughscope::image {

// The smallest sphere radius accepted, px: below it a pixel spans more than ~10° of normals.
inline constexpr double kMirrorSphereMinRadiusPx = 5.0;

struct MirrorSphereOptions {
    Eigen::Vector3d view = Eigen::Vector3d(0.0, 0.0, 1.0);  // V, camera frame, unit, V_z > 0
    // Pixels of the highlight: those above b + threshold_fraction · (peak − b) (b: the median of
    // the disc, peak: its largest channel average, saturated pixels included), in (0, 1).
    double threshold_fraction = 0.5;
    // Standard uncertainty (k = 1) of each of the circle's cx, cy and r, px, in [0, r].
    double circle_uncertainty_px = 0.5;
    // The floor of the highlight centroid's standard uncertainty (per axis, px, ≥ 0): pixel
    // quantisation and a lobe that is not quite symmetric. At most r.
    double centroid_floor_px = 0.1;
    // A highlight farther than this fraction of r from the centre is near the limb, where the
    // light's direction changes fast with the highlight's position (a warning), in (0, 1].
    double limb_warning_rho = 0.9;
};

// Throws InvalidArgument naming the field and its valid range.
void check_mirror_sphere_options(const MirrorSphereOptions& options);

struct MirrorSphereLight {
    Eigen::Vector3d light = Eigen::Vector3d(0.0, 0.0, 1.0);  // L, camera frame, unit
    double theta_deg = 0.0;  // polar angle of L from +z (the camera axis), [0°, 180°]
    double phi_deg = 0.0;    // azimuth of L from +x towards +y, (−180°, 180°]
    // Standard uncertainty (k = 1) of L's direction: the RMS angle between the measured and the
    // true L, from the highlight centroid's and the circle's uncertainties (docs/calibration.md).
    double angle_uncertainty_deg = 0.0;
    Eigen::Vector3d normal = Eigen::Vector3d(0.0, 0.0, 1.0);  // at the highlight: (L + V)/|L + V|
    // The highlight: the image point whose normal bisects L and V (image coordinates, px), its
    // distance from the centre / r, and its centroid's standard uncertainty (per axis, px).
    double highlight_x_px = 0.0, highlight_y_px = 0.0;
    double highlight_rho = 0.0;
    double highlight_uncertainty_px = 0.0;
    CircleFit circle;                     // the circle used
    std::size_t disc_pixels = 0;          // pixels searched: centre inside the circle (∩ mask)
    std::size_t highlight_pixels = 0;     // pixels of the highlight (the chosen blob)
    std::size_t saturated_pixels = 0;     // of which flagged saturated
    std::size_t blobs = 0;                // connected groups above the threshold (≥ 1)
    double background = 0.0, peak = 0.0;  // the disc's median and largest channel average
    double threshold = 0.0;               // the level of the highlight's pixels
    std::vector<std::string> warnings;    // near the limb; several blobs; a large highlight
};

// The light's direction from the highlight on a mirror sphere of circle (cx, cy, r) in `image`,
// searched among the pixels whose centre lies inside the circle and, when `sphere_mask` is given
// (width · height bytes, nonzero = search), on the mask. The highlight is the blob (8-connected
// pixels above the threshold) of the largest summed brightness above the background; its
// centroid is the brightness-weighted mean of the reflected directions R of its pixels (an
// orthographic mirror sphere samples directions uniformly, so this is the lobe's centre also
// where the blob is stretched near the limb); L is that mean, normalised.
// Throws InvalidArgument for an inconsistent image or mask, bad options (also an uncertainty
// above r), a circle that is not
// finite, has r < kMirrorSphereMinRadiusPx or does not lie inside the image; DataError when the
// disc holds no highlight (peak not above the background: the message gives both).
MirrorSphereLight mirror_sphere_light(const LinearImage& image, const CircleFit& circle,
                                      const std::vector<std::uint8_t>* sphere_mask = nullptr,
                                      const MirrorSphereOptions& options = {});

// The circle of a sphere given as a mask of its pixels (width · height bytes, nonzero = sphere):
// centre = the mean of the pixel centres, r = √(N / π). Throws InvalidArgument when the mask has
// the wrong size or fewer than π · kMirrorSphereMinRadiusPx² pixels.
CircleFit circle_from_mask(const std::vector<std::uint8_t>& mask, std::size_t width,
                           std::size_t height);

// The pieces of the geometry, for tests and front ends.
// The normal of the circle's point (x, y) (ρ clamped to 1).
Eigen::Vector3d mirror_sphere_normal(double x_px, double y_px, const CircleFit& circle);
// The mirror reflection of the view direction V about the normal n: 2(n·V)n − V.
Eigen::Vector3d reflect_view(const Eigen::Vector3d& normal, const Eigen::Vector3d& view);
// θ (from +z) and φ (from +x towards +y) of a direction, degrees.
double polar_angle_deg(const Eigen::Vector3d& direction);
double azimuth_deg(const Eigen::Vector3d& direction);

}  // namespace roughscope::image
