// The cylinder profile of §5.2 (Fig. 8) as named steps; measure_cylinder_profile (cylinder.cpp)
// runs them in this order. Formulas in docs/curved-objects.md ("Cylinder axis", "Cylinder
// profile").
//   1. geometry  (cylinder_geometry.cpp): the axis (given, or fitted to the silhouette) and the
//      bins of the normal angle α = asin(d/R) across it (d the signed distance from the axis,
//      R the radius; θi = |α| for L = V), resolved by 1/8-px sub-bins, and 1-px slices along it;
//   2. band scan (cylinder_scan.cpp, cylinder_scan_segments.cpp): one pass over the pixels in
//      bands of rows, summing the brightness per bin, per half-sub-bin and per slice of a bin;
//   3. bins      (cylinder_bins.cpp): brightness against incidence angle — each bin's mean,
//      standard errors and geometry nodes, normalised by the maximum (§2);
//   4. fits      (cylinder_fit.cpp): σ/T of the very-rough forms (Eq. 9, Eq. 10) per correlation
//      through the fit engine;
//   5. departure (cylinder_fit.cpp): each model's curve (Lambert, Eq. 7, 9, 10), the angle where
//      it leaves the data (next to Caron's θK, §3.5), and the dark-limb check of a detected axis.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "object_profile.hpp"
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image::detail {

// ---------------------------------------------------------------------------------------------
// 1. Geometry

// Sub-bins of the distance across the axis per pixel (resolution of a bin's pixel distribution).
inline constexpr double kSubBinsPerPx = 8.0;

// Where the cylinder is.
struct CylinderLocation {
    CylinderAxis axis;                // axis.detected: fitted to the silhouette
    std::vector<RowRun> object_rows;  // the silhouette, one run a row; empty: every pixel
    double silhouette_level = 0.0;    // the silhouette's level, linear scale (0: axis given)
};

// The axis of options.axis (the image's values then checked here) or fitted to the image's
// silhouette (fit_cylinder_axis on find_outline, which checks the values as it reads them).
CylinderLocation locate_cylinder(const LinearImage& image, const CylinderOptions& options);

// The bins of the normal angle α = asin(d/R) about the axis (d the signed distance from the axis
// along across(), silhouette.hpp), by the half: Right x = α, Left x = −α, Both x = α + π/2, bin
// ⌊x / width⌋. A bin's pixels are found exactly from sub-bins of d of 1/8 px, each holding at
// most one bin edge, and slices of 1 px along the axis.
struct CylinderBinning {
    CylinderAxis axis;
    CylinderHalf half = CylinderHalf::Right;
    double bin_width_rad = 0.0;
    double limb_fraction = 1.0;  // pixels with |d| > limb_fraction · R are in no bin
    std::size_t bins = 0;        // ⌈(π/2, or π for Both) / bin width⌉
    std::size_t sub_bins = 0;    // sub-bin k covers d ∈ [k/8 − R, (k + 1)/8 − R)
    // Per sub-bin: the bin edge inside it (d, px), +∞ when it holds none.
    std::vector<double> split;
    // Per half-sub-bin (2k: d below split[k], 2k + 1: at or above it): its bin, −1 for none.
    std::vector<std::int32_t> sub_bin;
    double t_min_px = 0.0;  // least t = (p − P)·a over the image's corners (P a point of the axis)
    std::size_t slices = 0;  // slice j holds t − t_min ∈ [j, j + 1)
    std::size_t bands = 0;   // bands of rows of the scan (scan_bands)

    // The bin of the pixels at distance d from the axis (−1: outside the half or the limb).
    std::int32_t bin_of(double across_px) const;
    // The lower end of sub-bin k, px.
    double sub_bin_low_px(std::size_t k) const;
};

// The bins of `axis` over an image of width × height pixels. Throws when the scan's
// accumulators (every band's bins and their slices) would pass the memory limit
// (check_memory's InvalidArgument).
CylinderBinning bin_cylinder(const CylinderAxis& axis, const CylinderOptions& options,
                             std::size_t width, std::size_t height);

// One point of a bin's pixel distribution: its geometry and the fraction of the bin's pixels.
struct ProfileNode {
    Geometry geometry;
    double weight = 0.0;
    bool lit = false;  // L and V above the horizon of the normal
};

// The node at s = d/R across a cylinder whose in-image across direction is (ux, uy) (image
// coordinates, y down): n = s û + √(1 − s²) ẑ with û = (ux, −uy, 0) in the camera frame, the
// geometry (θi, θs, φs) = geometry_from_vectors(n, L, V) (§2); for L = V, θi = |asin(s)|.
ProfileNode cylinder_node(double s, double weight, double ux, double uy,
                          const Eigen::Vector3d& light, const Eigen::Vector3d& view);

// The number of bands of rows of the scan over an image of `height` rows: at most 8, of at least
// 256 rows (fixed, so that the sums do not depend on the number of threads).
std::size_t scan_bands(std::size_t height);

// ---------------------------------------------------------------------------------------------
// 2. Band scan

// Per-bin sums of the channel average v of its used pixels.
struct BinSums {
    double sum = 0, sum2 = 0;  // Σv, Σv²
    double diff2 = 0;          // Σ(v − v')² over neighbours v' along the axis in the same bin
    std::size_t count = 0, diffs = 0;
    std::size_t flagged = 0;  // pixels of the bin left out (image.hpp kPixel* flags)
};

struct CylinderSums {
    std::vector<BinSums> bins;               // per bin
    std::vector<std::uint32_t> sub_count;    // per half-sub-bin: used pixels
    std::vector<double> sub_d;               // per half-sub-bin: Σ d, px
    std::vector<double> slice_sum;           // [bin · slices + slice]: Σ v
    std::vector<std::uint32_t> slice_count;  // [bin · slices + slice]: used pixels
    std::size_t pixels_flagged = 0;          // in a bin, left out
};

// How the scan visits the pixels. Fastest: with a region, pixel by pixel; without, in segments
// of a row classified at their ends only (one path for an axis within 45° of the columns, one
// for an axis closer to the rows). PerPixel: pixel by pixel always (the segments' reference).
enum class ScanPath { Fastest, PerPixel };

// One pass over the used pixels — in object_rows (empty: every pixel), in region (width · height
// bytes, nonzero = use; nullptr: every pixel), in a bin, without a flag (counted) — on `threads`
// worker threads (0 = all cores) over binning.bands fixed bands of rows, whose sums are added in
// band order: the result does not depend on the number of threads. Neighbours for the pixel
// noise: along the image direction closer to the axis (the previous row for a steep axis, the
// previous column otherwise).
CylinderSums scan_cylinder(const LinearImage& image, const std::uint8_t* region,
                           const CylinderBinning& binning, const std::vector<RowRun>& object_rows,
                           std::size_t threads, ScanPath path = ScanPath::Fastest);

// ---------------------------------------------------------------------------------------------
// 3. Bins: brightness against incidence angle

struct CylinderBins {
    std::vector<ProfileBin> bins;                 // increasing θi, normalised (§2)
    std::vector<std::vector<ProfileNode>> nodes;  // per bin: its pixels' distribution across d
    double maximum = 0.0;                         // the raw mean of the brightest bin
    std::size_t pixels_used = 0;
    std::vector<std::string> warnings;  // bins left out, flagged pixels
};

// The profile's bins from the scan's sums: per bin the mean m = Σv/n, the standard errors from
// the slices along the axis and from the pixel noise, the geometry at the mean d and at most 32
// nodes (pixel count, mean d) of the sub-bins; bins with fewer than options.min_pixels_per_bin
// pixels or with L or V below the horizon of their mean normal left out (with a warning); then
// normalised by the largest mean and marked in_fit. Throws DataError (naming `image_name`) with
// fewer than 3 bins or no positive brightness.
CylinderBins profile_bins(const CylinderSums& sums, const CylinderBinning& binning,
                          const CylinderOptions& options, std::string_view image_name);

// ---------------------------------------------------------------------------------------------
// 4. Fits

// The σ/T fit of ProfileFit (cylinder.hpp): minimise Σ w_b (K M_b(σ/T) − E_b)² over the bins
// with in_fit, w_b = 1/SE_b², M_b = Σ_nodes weight · very_rough_brightness (Eq. 4 or Eq. 5 with
// `factor`), by solve_least_squares (fit/engine.hpp). NotIdentifiable, unsolved, with fewer than
// 3 such bins.
ProfileFit fit_profile(const std::vector<ProfileBin>& bins,
                       const std::vector<std::vector<ProfileNode>>& nodes, Correlation correlation,
                       GeometricFactor factor, Radiometry radiometry);

struct CylinderFits {
    ProfileFit gaussian;
    ProfileFit exponential;
    Correlation preferred = Correlation::Gaussian;  // lower AIC (the one fitted, when one is)
};

// fit_profile (object_profile.hpp) for both correlations with options.factor and radiometry,
// side by side on options.threads.
CylinderFits fit_cylinder_profile(const CylinderBins& bins, const CylinderOptions& options);

// ---------------------------------------------------------------------------------------------
// 5. Curves and departure

// Σ_nodes weight · f(geometry) per bin (unlit nodes contribute 0).
template <class F>
std::vector<double> bin_model_averages(const std::vector<std::vector<ProfileNode>>& nodes, F&& f) {
    std::vector<double> out(nodes.size(), 0.0);
    for (std::size_t b = 0; b < nodes.size(); ++b)
        for (const ProfileNode& n : nodes[b])
            if (n.lit) out[b] += n.weight * f(n.geometry);
    return out;
}

// The departure rule of CylinderOptions: the first bin from which `run` consecutive bins (or all
// remaining, when fewer) have |prediction − brightness| > k · standard_error; none when the
// prediction never leaves the data.
std::optional<std::size_t> departure_bin(const std::vector<ProfileBin>& bins,
                                         const std::vector<double>& prediction, double k,
                                         std::size_t run);

// The curve of `model` at σ/T (ignored for Lambert): its bin averages over the nodes normalised
// by their maximum, the RMS difference from the bins' brightness, and the departure (departure_bin
// with options.departure_k and departure_bins).
ProfileModelCurve profile_curve(ProfileModel model, std::optional<double> sigma_over_T,
                                const CylinderBins& bins, const CylinderOptions& options);

// The warning of a detected axis whose limb looks dark: the bin nearest α = 80° (or the outermost
// one, beyond 60°) below 10× the silhouette's level (relative to `maximum`); none otherwise.
std::optional<std::string> dark_limb_warning(const std::vector<ProfileBin>& bins, double maximum,
                                             double silhouette_level);

}  // namespace roughscope::image::detail
