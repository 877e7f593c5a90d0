// Roughness maps (paper §5.1, §4.2, §3.5): σ/T per pixel or per tile of an object photographed
// under two light directions, and the class of each part (slightly, moderately, very rough).
// Every formula is in docs/maps.md; the symbols below follow it.
//
// Brightness of capture k at pixel p: x_k(p) = (channel average of the LinearImage at p) / s_k
// (s_k: the exposure scale, as in image/measure.hpp). A pixel is used when neither image flags
// it (image.hpp kPixel*). For a tile W (window_px × window_px; the last row/column of tiles may be
// smaller) of n used pixels:
//   m_k = Σ x_k / n,  v_k = Σ (x_k − m_k)² / (n − 1),  c_12 = Σ (x_1 − m_1)(x_2 − m_2) / (n − 1)
//   E1/E2 = m_1 / m_2,   var(ln E1/E2) = (v_1/m_1² + v_2/m_2² − 2 c_12/(m_1 m_2)) / n
// (first order; the covariance removes what the two images share, e.g. a texture or shading).
// Per pixel (window_px = 1) the ratio is the pixel's own x_1/x_2 and its variance that of one
// pixel, n·var above over the used pixels of the (2·kPixelNoiseRadius + 1)² neighbourhood.
// σ/T from E1/E2: Eq. 17 (Gaussian) and Eq. 19 (exponential) for a flat sample seen along its
// normal, through a table of the inverse (RatioInverseTable) built once per map; the two-geometry
// solver of estimation.hpp for any other flat geometry (also tabulated) and, per tile, for a
// normal map. sd(σ/T) = |dσ/T / d ln(E1/E2)| · sd(ln E1/E2).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "roughscope/core/memory.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/maps/registration.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image {

// ---------------------------------------------------------------------------------------------
// Classes by σ/T (§3.1, §5.1: slightly rough σ ≪ T, moderately σ ≈ T, very rough σ ≫ T).
// (σ/T)² is what enters the very-rough forms (T²/σ² in Eq. 16–19), as σ² enters g; the library
// draws the g lines one decade either side of g = 1 (validity.hpp), so the σ/T lines are one
// decade of (σ/T)² either side of σ/T = 1: 10^(−1/2) and 10^(1/2). In slopes: RMS slope
// m = √2 σ/T = 0.45 (24°) and 4.5 (77°); Caron's θK = 66° and 13° (validity.hpp).
inline constexpr double kSlightlyRoughMaxSigmaOverT = 0.31622776601683794;  // 10^(−1/2)
inline constexpr double kVeryRoughMinSigmaOverT = 3.1622776601683795;       // 10^(1/2)

// Class layer codes (RoughnessClass order; kClassNone where there is no estimate).
inline constexpr std::uint8_t kClassSlightlyRough = 0;
inline constexpr std::uint8_t kClassModeratelyRough = 1;
inline constexpr std::uint8_t kClassVeryRough = 2;
inline constexpr std::uint8_t kClassNone = 255;

// The class of σ/T against the two thresholds (σ/T < slightly_max: slightly; > very_min: very).
RoughnessClass roughness_class_of_sigma_over_T(
    double sigma_over_T, double slightly_rough_max = kSlightlyRoughMaxSigmaOverT,
    double very_rough_min = kVeryRoughMinSigmaOverT);

// Per-pixel mode: the noise of a pixel is estimated from the (2R + 1)² neighbourhood, R = 2.
inline constexpr std::size_t kPixelNoiseRadius = 2;

// ---------------------------------------------------------------------------------------------
// The inverse of a brightness-ratio model, tabulated.
//
// For two fixed geometries the model ratio M(x) (x = σ/T, or T with σ known) is monotone in x.
// The table holds nodes x_j = exp(ln lower + j h) (h = ln(upper/lower)/(nodes − 1)) with
// y_j = ln M(x_j) and dy/dx_j (M of estimation.hpp: model_ratio_very_rough, whose slope at
// normal view is that of Eq. 17/19, d_sigma_over_T_*_d_log_ratio; a central difference of ln M
// otherwise), the nodes where M is a finite double; x(y) between two nodes is the cubic Hermite
// interpolant in y with the slopes dx/dy = 1/(dy/dx). With the defaults (x in [1e-4, 1e4], 4097
// nodes) its error against Eq. 17/19 is below 1e-9 relative (tests/cpp/maps/test_maps.cpp
// measures it); ratios outside [y_0, y_last] (outside the model's range, or σ/T outside [lower,
// upper]) have no solution.
struct RatioInverseTableOptions {
    double lower = 1e-4;  // the unknown's range
    double upper = 1e4;
    std::size_t nodes = 4097;
};

class RatioInverseTable {
  public:
    // σ/T at two geometries: the very-rough model ratio of estimation.hpp (Eq. 16/18 when both
    // are normal view, θs = 0). InvalidArgument for bad geometries, options, or two geometries
    // the ratio cannot tell apart.
    static RatioInverseTable sigma_over_T(const Geometry& geom1, const Geometry& geom2,
                                          Correlation correlation,
                                          const TwoGeometryOptions& model = {},
                                          const RatioInverseTableOptions& table = {});
    // T (µm) with σ known: ln of model_ratio_diffuse (the regime of `model`).
    static RatioInverseTable correlation_length(const Geometry& geom1, const Geometry& geom2,
                                                double sigma_um, Correlation correlation,
                                                const TwoGeometryOptions& model = {},
                                                const RatioInverseTableOptions& table = {});

    struct Value {
        double x = 0.0;              // the unknown
        double dx_dlog_ratio = 0.0;  // d x / d ln(E1/E2)
    };
    // x at ln(E1/E2); nullopt when outside the table. The interval is found through an index of
    // 4 buckets per interval, uniform in a monotone integer stand-in for ln(y − y_0) − ln(y_n − y)
    // (the nodes, uniform in ln x, crowd logarithmically towards the ends), and a short scan of the
    // bucket's intervals; `hint` receives it.
    std::optional<Value> lookup(double log_ratio, std::size_t& hint) const;
    std::optional<Value> lookup(double log_ratio) const {
        std::size_t hint = 0;
        return lookup(log_ratio, hint);
    }
    // The most intervals one bucket of the index meets (the look-up's longest scan + 1).
    std::size_t max_intervals_per_bucket() const;
    // lookup's arithmetic without the optional: false (v untouched) where lookup gives nullopt.
    // Inline, for the per-pixel map.
    bool find(double log_ratio, Value& v, std::size_t& interval) const {
        if (!(log_ratio >= y_.front() && log_ratio <= y_.back())) return false;
        const std::size_t b = bucket_of(log_ratio);
        std::size_t j = bucket_first_interval_[b];
        const std::size_t last = bucket_first_interval_[b + 1];
        // Two steps without a branch (the buckets of the tables here meet at most 3 intervals),
        // then the rest of a longer bucket.
        j += static_cast<std::size_t>(j < last && y_[j + 1] <= log_ratio);
        j += static_cast<std::size_t>(j < last && y_[j + 1] <= log_ratio);
        while (j < last && y_[j + 1] <= log_ratio) ++j;
        interval = j;
        // The cubic Hermite interpolant in y between nodes j and j + 1.
        const std::array<double, 5>& c = coefficients_[j];
        const double t = (log_ratio - y_[j]) * c[4];
        const double x = c[0] + t * (c[1] + t * (c[2] + t * c[3]));
        if (!(x > 0.0) || !(x <= std::numeric_limits<double>::max())) return false;
        v.x = x;
        v.dx_dlog_ratio = (c[1] + t * (2.0 * c[2] + t * 3.0 * c[3])) * c[4];
        return true;
    }
    // find(ln ratio, …) without the logarithm where it can (the per-pixel map). Near the table's
    // anchor — its end of larger x, where σ/T → ∞ at the model ratio's finite bound — x is a
    // smooth function of u = s·(ratio·e^(−y_a) − 1) (y_a the anchor's ln ratio; s = +1 when it
    // is y_0, −1 when it is y_last), and the bits of u as a double select a bin: 64 per octave of
    // u over [2^−48, 2^80) (the exponent and the top 6 bits of the mantissa). In a bin x is the
    // cubic Hermite interpolant, in the bin's position t (the mantissa's other bits), of find's x
    // and slope at the bin's two ends. A bin is used only when both ends lie inside the table and
    // its middle agrees with find (kRatioBinTolerance); every other ratio (outside the bins,
    // ≤ 0, NaN) goes through find(std::log(ratio), …). `interval` is written by that path only.
    bool find_ratio(double ratio, Value& v, std::size_t& interval) const {
        const double u = anchor_sign_ * (ratio * inv_anchor_ratio_ - 1.0);
        const auto bits = std::bit_cast<std::uint64_t>(u);
        const std::uint64_t bin = (bits >> kRatioBinShift) - ratio_bin_key_min_;
        if (bin < ratio_bins_.size() / 5) {
            const double* c = ratio_bins_.data() + 5 * bin;
            if (c[0] > 0.0) {
                const double t = static_cast<double>(bits & kRatioBinMantissa) * kRatioBinT;
                v.x = c[0] + t * (c[1] + t * (c[2] + t * c[3]));
                v.dx_dlog_ratio =
                    (c[1] + t * (2.0 * c[2] + t * 3.0 * c[3])) * c[4] * (anchor_sign_ + u);
                return true;
            }
        }
        return find(std::log(ratio), v, interval);
    }
    // find_ratio over arrays, its bins only (a loop without branches, vectorised, in the build of
    // map_instruction_set: the same numbers): x[i] and dx_dlog_ratio[i] at ratio[i] where its
    // bin is used, both NaN elsewhere. True when a ratio that is not NaN missed the bins (find
    // at its logarithm is the caller's).
    bool find_ratio_bins(std::size_t n, const double* ratio, double* x,
                         double* dx_dlog_ratio) const;
    // The largest relative difference between a ratio bin's cubic and find at the bin's middle
    // for the bin to be used: x (beyond what the rounding of ln ratio alone moves find's x by)
    // and the slope (find's own slope is a cubic's derivative, good to ~1e-7).
    static constexpr double kRatioBinTolerance = 4e-9;
    static constexpr double kRatioBinSlopeTolerance = 1e-5;
    // How many of the ratio bins are used (the rest go through find(ln ratio)).
    std::size_t ratio_bins_used() const;
    // The ratios E1/E2 the table inverts (open interval).
    RatioRange ratio_range() const;
    std::size_t size() const { return y_.size(); }
    // The nodes: x_j (increasing or decreasing) and y_j = ln M(x_j) (increasing).
    std::span<const double> node_x() const { return x_; }
    std::span<const double> node_log_ratio() const { return y_; }

  private:
    void build_coefficients();
    void build_ratio_bins();
    std::vector<double> y_, x_, dxdy_;  // y increasing
    // Per interval j: x = c0 + c1 t + c2 t² + c3 t³, t = (y − y_j)·c4 (the Hermite cubic).
    std::vector<std::array<double, 5>> coefficients_;
    // A monotone stand-in for ln(y − y_0) − ln(y_n − y): the bits of a positive double, read as
    // an integer, grow monotonically and about linearly with its log2.
    std::int64_t bucket_key(double log_ratio) const {
        const double front = std::max(log_ratio - y_.front(), key_floor_front_);
        const double back = std::max(y_.back() - log_ratio, key_floor_back_);
        return std::bit_cast<std::int64_t>(front) - std::bit_cast<std::int64_t>(back);
    }
    std::size_t bucket_of(double log_ratio) const {
        const std::size_t buckets = bucket_first_interval_.size() - 1;
        const double at = static_cast<double>(bucket_key(log_ratio) - key_min_) * bucket_scale_;
        return std::min(buckets - 1, static_cast<std::size_t>(std::max(0.0, at)));
    }
    // bucket_first_interval_[b]: the interval holding the smallest y of bucket b (b = 0 …
    // buckets; [b + 1] bounds the intervals of bucket b).
    std::vector<std::uint32_t> bucket_first_interval_;
    double key_floor_front_ = 0.0, key_floor_back_ = 0.0;
    std::int64_t key_min_ = 0;
    double bucket_scale_ = 0.0;
    // The ratio bins of find_ratio, five numbers each: x = c0 + t (c1 + t (c2 + t c3)),
    // c4 = 1/(bin width in u); c0 = 0 where the bin is not used.
    static constexpr int kRatioBinShift = 52 - 6;
    static constexpr std::uint64_t kRatioBinMantissa = (std::uint64_t{1} << kRatioBinShift) - 1;
    static constexpr double kRatioBinT =
        1.0 / static_cast<double>(std::uint64_t{1} << kRatioBinShift);
    std::vector<double> ratio_bins_;
    std::uint64_t ratio_bin_key_min_ = 0;
    double anchor_sign_ = 1.0, inv_anchor_ratio_ = 1.0, anchor_log_ratio_ = 0.0;
};

// ---------------------------------------------------------------------------------------------
// Input

// One photograph. The image is not copied: it must outlive roughness_map.
struct MapCapture {
    const LinearImage* image = nullptr;
    std::string name;  // for messages (default: image->info.source)
    // Flat sample: the one geometry of every pixel (paper frame, radians).
    Geometry geometry;
    double exposure_scale = 1.0;  // s_k: brightness = value / s_k (> 0)
    // Non-flat object (MapOptions::normal_map given): the light and view directions, unit vectors
    // in the camera frame (x right, y up, z toward the camera); each pixel's geometry is
    // geometry_from_vectors(n, L, V). Required then; ignored for a flat sample.
    std::optional<Eigen::Vector3d> light;
    std::optional<Eigen::Vector3d> view;
};

struct MapOptions {
    // 1: per pixel; N ≥ 2: tiles of N × N pixels. In [1, 4096].
    std::size_t window_px = 8;
    // A tile needs at least this fraction of its pixels used (and ≥ 2 pixels); per pixel, the
    // pixel itself used and ≥ 3 used in its neighbourhood. In (0, 1].
    double min_used_fraction = 0.5;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    double wavelength_um = 0.555;
    // Known σ (µm): T per pixel/tile and the class by g (validity.hpp roughness_class) too.
    std::optional<double> sigma_um;
    double sigma_um_stderr = 0.0;
    // The correlation of T given σ and of the class by σ/T.
    Correlation correlation = Correlation::Gaussian;
    // Registration of capture 2 against capture 1 (registration.hpp): a shift above max_shift_px
    // (with a peak-to-sidelobe ratio ≥ min_peak_to_sidelobe: the images share structure) is
    // refused (DataError) unless allow_misregistration; a lower PSR only warns. With a normal
    // map a shift only warns: a curved object's shading moves with the light, which phase
    // correlation cannot tell from a movement of the camera.
    double max_shift_px = 1.0;
    bool allow_misregistration = false;
    double min_peak_to_sidelobe = 8.0;
    bool check_registration = true;
    RegistrationOptions registration;
    double slightly_rough_max_sigma_over_T = kSlightlyRoughMaxSigmaOverT;
    double very_rough_min_sigma_over_T = kVeryRoughMinSigmaOverT;
    // Layers beyond those of every map (σ/T of `correlation`, its standard error and the class
    // by σ/T; with σ known, T, its error and the class by g): σ/T and its standard error of the
    // other correlation too, and the ratio E1/E2. (Off by default: a 24-MP per-pixel map is
    // 9 bytes per pixel without them, 21 with both.) The region statistics give both
    // correlations either way.
    bool both_correlations = false;
    bool ratio_layer = false;
    // Non-flat object: 3 floats per pixel (n_x, n_y, n_z, camera frame), row-major; a non-finite
    // normal marks a pixel off the object (not used). Empty: a flat sample.
    std::span<const float> normal_map;
    // Regions: one int32 per pixel (−1 = none, else an index into region_names); empty = none.
    std::span<const std::int32_t> region_labels;
    std::vector<std::string> region_names;
    RatioInverseTableOptions table;
    // Worker threads over bands of rows (0 = all cores; maps below 65536 cells and normal maps
    // use one). The result does not depend on it.
    std::size_t threads = 0;
};

// ---------------------------------------------------------------------------------------------
// Result

struct ClassStatistics {
    RoughnessClass roughness_class = RoughnessClass::SlightlyRough;
    std::size_t count = 0;                      // pixels/tiles of the class
    double fraction = 0.0;                      // of the valid pixels/tiles
    std::optional<Estimate> mean_sigma_over_T;  // of MapOptions::correlation; stderr of the mean
};

struct RegionMapStatistics {
    std::string name;
    std::size_t count = 0;  // valid pixels/tiles wholly in the region
    std::size_t missing = 0;
    // σ/T of the region with its standard error. A flat sample: the inverse (Eq. 17 / 19 or the
    // two-geometry model) at the mean of the cells' ln(E1/E2), its error the standard error of
    // that mean through the inverse's slope (unbiased where the cells' σ/T are noisy and the
    // inverse curved). A normal map: the mean of the cells' σ/T, error sd / √count.
    std::optional<Estimate> mean_sigma_over_T_gaussian;
    std::optional<Estimate> mean_sigma_over_T_exponential;
    std::optional<Estimate> mean_T_um;          // σ known
    std::array<std::size_t, 3> class_counts{};  // by σ/T (RoughnessClass order)
};

using MapLayerValues = std::vector<float, DefaultInitAllocator<float>>;
using MapClassCodes = std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>>;

struct RoughnessMap {
    std::size_t width = 0;  // of the map (pixels or tiles): ceil(image width / window_px)
    std::size_t height = 0;
    std::size_t window_px = 1;
    std::size_t image_width = 0, image_height = 0;
    // Layers, width · height, row-major, NaN where missing; empty where not made. σ/T and its
    // error of MapOptions::correlation always, of the other correlation with
    // MapOptions::both_correlations; E1/E2 with MapOptions::ratio_layer. (DefaultInitAllocator:
    // the map writes every cell once, each band of rows from its own thread, not a fill first.)
    MapLayerValues E1_over_E2;
    MapLayerValues sigma_over_T_gaussian, sigma_over_T_gaussian_stderr;
    MapLayerValues sigma_over_T_exponential, sigma_over_T_exponential_stderr;
    MapLayerValues T_um, T_um_stderr;  // σ known only (else empty)
    // Class by σ/T of MapOptions::correlation (kClass* codes), and by g when σ is known.
    MapClassCodes roughness_class;
    MapClassCodes roughness_class_g;  // σ known only
    std::size_t valid = 0;            // pixels/tiles with a σ/T (of MapOptions::correlation)
    std::size_t missing = 0;          // too few used pixels (flagged, off the object)
    std::size_t no_solution = 0;      // a ratio the model does not produce
    // The same for the other correlation (MapOptions::both_correlations only).
    std::optional<std::size_t> no_solution_other;
    std::optional<Registration> registration;
    std::array<ClassStatistics, 3> classes;
    std::vector<RegionMapStatistics> regions;
    std::vector<std::string> warnings;
    std::string method;  // "table (Eq. 17/19)", "table (two-geometry model)", "solver per tile"

    // The σ/T layer and its standard error of correlation c (empty where not made).
    MapLayerValues& sigma_over_T(Correlation c) {
        return c == Correlation::Gaussian ? sigma_over_T_gaussian : sigma_over_T_exponential;
    }
    const MapLayerValues& sigma_over_T(Correlation c) const {
        return c == Correlation::Gaussian ? sigma_over_T_gaussian : sigma_over_T_exponential;
    }
    MapLayerValues& sigma_over_T_stderr(Correlation c) {
        return c == Correlation::Gaussian ? sigma_over_T_gaussian_stderr
                                          : sigma_over_T_exponential_stderr;
    }
    const MapLayerValues& sigma_over_T_stderr(Correlation c) const {
        return c == Correlation::Gaussian ? sigma_over_T_gaussian_stderr
                                          : sigma_over_T_exponential_stderr;
    }
};

// The correlation that is not c.
inline Correlation other_correlation(Correlation c) {
    return c == Correlation::Gaussian ? Correlation::Exponential : Correlation::Gaussian;
}

// Throws InvalidArgument (fewer than 2 captures, a null image, images of different sizes, a
// non-finite value in either of the two images (checked as the map reads them), window_px or
// other options out of range, a normal map or region labels of the wrong size,
// missing light/view for a normal map) or DataError (a flat sample whose capture 2 moved against
// capture 1 by more than max_shift_px: the message gives the shift and the threshold). With more
// than two captures the first two are used and a warning says so (a per-tile least-squares fit is
// left to image/measure.hpp's region measurement).
RoughnessMap roughness_map(const std::vector<MapCapture>& captures, const MapOptions& options);

// The per-pixel map's row loops and RatioInverseTable::find_ratio_bins are built by the compiler
// for several instruction sets (target clones: x86-64-v4 (AVX-512) and x86-64-v3 (AVX2) beside
// the baseline), the best the processor runs chosen when the library is loaded, and once more
// for the baseline alone (Baseline: the reference of the tests and benchmarks). Every build does
// the same arithmetic (the row loops are compiled with -ffp-contract=off: no fused
// multiply-add), so every build gives the same map.
enum class MapInstructionSet { Baseline, Best };
// The build the row loops use, process-wide (for tests and benchmarks; default Best); returns
// the previous one.
MapInstructionSet limit_map_instruction_set(MapInstructionSet highest);
// The build the row loops use now.
MapInstructionSet map_instruction_set();

}  // namespace roughscope::image
