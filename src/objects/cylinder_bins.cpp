// Step 3 of the cylinder profile (cylinder_steps.hpp): brightness against incidence angle — the
// bins from the scan's sums (docs/curved-objects.md, "Cylinder profile": along the axis, geometry
// of a bin, normalisation).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cylinder_steps.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {
namespace {

constexpr std::size_t kNodesPerBin = 32;  // geometry nodes of a bin's model average
// Floor of a bin's standard error, in units of the profile's maximum: a quantisation step of a
// 14-bit camera (noise-free synthetic data have none of their own).
constexpr double kMinRelativeStandardError = 1e-4;

// A bin and its nodes, before normalisation.
struct BinWork {
    ProfileBin bin;
    std::vector<ProfileNode> nodes;
};

// Bin b's count, mean and standard errors (raw scale): from the pixel noise, σ² = Σ Δ² / (2 N_Δ)
// (the variance about the mean without neighbour differences), and from the slices along the
// axis, SE = √(J/(J − 1) · Σ n_j² (m_j − m)²) / n (the ratio-estimator variance).
ProfileBin bin_statistics(const CylinderSums& sums, std::size_t b, std::size_t n_slices) {
    const BinSums& bs = sums.bins[b];
    ProfileBin pb;
    const auto n = static_cast<double>(bs.count);
    pb.count = bs.count;
    pb.flagged = bs.flagged;
    pb.raw_mean = bs.sum / n;
    const double var =
        bs.count > 1 ? std::max(0.0, (bs.sum2 - n * pb.raw_mean * pb.raw_mean) / (n - 1.0)) : 0.0;
    const double noise_var = bs.diffs >= 2 ? bs.diff2 / (2.0 * static_cast<double>(bs.diffs)) : var;
    pb.stderr_pixel = std::sqrt(noise_var / n);
    double s2 = 0;
    std::size_t J = 0;
    for (std::size_t j = 0; j < n_slices; ++j) {
        const std::uint32_t nj = sums.slice_count[b * n_slices + j];
        if (nj == 0) continue;
        ++J;
        const double e = sums.slice_sum[b * n_slices + j] - static_cast<double>(nj) * pb.raw_mean;
        s2 += e * e;  // n_j² (m_j − m)²
    }
    pb.slices = J;
    pb.stderr_slices =
        J >= 2 ? std::sqrt(s2 * static_cast<double>(J) / static_cast<double>(J - 1)) / n : 0.0;
    return pb;
}

// A bin's nodes: its half-sub-bins `subs` (in order) grouped into at most kNodesPerBin runs
// (pixel count / n, mean d); `across_sum` gets Σd over them.
std::vector<ProfileNode> bin_nodes(const std::vector<std::size_t>& subs, const CylinderSums& sums,
                                   double n, const CylinderBinning& g,
                                   const CylinderOptions& options, double& across_sum) {
    const double R = g.axis.radius_px;
    const double ux = g.axis.across_x(), uy = g.axis.across_y();
    std::vector<ProfileNode> nodes;
    const std::size_t group = (subs.size() + kNodesPerBin - 1) / kNodesPerBin;
    double dsum = 0;
    for (std::size_t k0 = 0; k0 < subs.size(); k0 += group) {
        double cnt = 0, ds = 0;
        for (std::size_t k = k0; k < std::min(subs.size(), k0 + group); ++k) {
            cnt += sums.sub_count[subs[k]];
            ds += sums.sub_d[subs[k]];
        }
        dsum += ds;
        nodes.push_back(cylinder_node(ds / cnt / R, cnt / n, ux, uy, options.light, options.view));
    }
    across_sum = dsum;
    return nodes;
}

// Normalised by the maximum (§2), the standard errors by the same factor; in_fit marked.
void normalise_bins(std::vector<BinWork>& kept, const CylinderOptions& options,
                    std::string_view image_name, CylinderBins& out) {
    for (const BinWork& wk : kept) out.maximum = std::max(out.maximum, wk.bin.raw_mean);
    if (!(out.maximum > 0))
        throw DataError(concat(image_name, ": the cylinder profile has no positive brightness"));
    for (BinWork& wk : kept) {
        ProfileBin& pb = wk.bin;
        pb.brightness = pb.raw_mean / out.maximum;
        pb.stderr_slices /= out.maximum;
        pb.stderr_pixel /= out.maximum;
        pb.standard_error =
            std::max({pb.stderr_slices, pb.stderr_pixel, kMinRelativeStandardError});
        pb.in_fit =
            pb.theta_i_rad <= deg_to_rad(options.fit_max_theta_i_deg) && pb.brightness > 0 &&
            pb.standard_error > 0 &&
            static_cast<double>(pb.flagged) <=
                options.fit_max_flagged_fraction * static_cast<double>(pb.flagged + pb.count);
        out.bins.push_back(pb);
        out.nodes.push_back(std::move(wk.nodes));
    }
}

}  // namespace

CylinderBins profile_bins(const CylinderSums& sums, const CylinderBinning& g,
                          const CylinderOptions& options, std::string_view image_name) {
    CylinderBins out;
    const double R = g.axis.radius_px;
    std::vector<BinWork> kept;
    std::size_t dropped_small = 0, dropped_dark = 0;
    // Each bin's used half-sub-bins, in order.
    std::vector<std::vector<std::size_t>> subs_of_bin(g.bins);
    for (std::size_t k = 0; k < 2 * g.sub_bins; ++k)
        if (g.sub_bin[k] >= 0 && sums.sub_count[k] > 0)
            subs_of_bin[static_cast<std::size_t>(g.sub_bin[k])].push_back(k);
    for (std::size_t b = 0; b < g.bins; ++b) {
        const BinSums& bs = sums.bins[b];
        out.pixels_used += bs.count;
        if (bs.count == 0) continue;
        if (bs.count < options.min_pixels_per_bin) {
            ++dropped_small;
            continue;
        }
        BinWork wk;
        wk.bin = bin_statistics(sums, b, g.slices);
        ProfileBin& pb = wk.bin;
        double dsum = 0;
        wk.nodes = bin_nodes(subs_of_bin[b], sums, static_cast<double>(bs.count), g, options, dsum);
        pb.across_px = dsum / static_cast<double>(bs.count);
        pb.alpha_rad = std::asin(std::clamp(pb.across_px / R, -1.0, 1.0));
        const ProfileNode centre = cylinder_node(pb.across_px / R, 1.0, g.axis.across_x(),
                                                 g.axis.across_y(), options.light, options.view);
        if (!centre.lit) {
            ++dropped_dark;  // L or V below the horizon of the bin's mean normal
            continue;
        }
        pb.geometry = centre.geometry;
        pb.theta_i_rad = pb.geometry.theta_i_rad;
        kept.push_back(std::move(wk));
    }
    if (dropped_small)
        out.warnings.push_back(concat(std::to_string(dropped_small), " bin(s) with fewer than ",
                                      std::to_string(options.min_pixels_per_bin),
                                      " used pixels left out"));
    if (dropped_dark)
        out.warnings.push_back(concat(std::to_string(dropped_dark),
                                      " bin(s) where the light or the viewer is below the "
                                      "surface's horizon left out"));
    if (sums.pixels_flagged)
        out.warnings.push_back(concat(std::to_string(sums.pixels_flagged),
                                      " flagged pixel(s) (saturated, clipped) left out"));
    if (kept.size() < 3)
        throw DataError(concat(image_name, ": the cylinder profile has ",
                               std::to_string(kept.size()), " bin(s) with at least ",
                               std::to_string(options.min_pixels_per_bin),
                               " usable pixels; at least 3 are needed"));
    const bool both = options.half == CylinderHalf::Both;
    std::stable_sort(kept.begin(), kept.end(), [&](const BinWork& x, const BinWork& y) {
        return both ? x.bin.alpha_rad < y.bin.alpha_rad : x.bin.theta_i_rad < y.bin.theta_i_rad;
    });
    if (both)  // the departure rule and plots run over increasing θi
        std::stable_sort(kept.begin(), kept.end(), [](const BinWork& x, const BinWork& y) {
            return x.bin.theta_i_rad < y.bin.theta_i_rad;
        });
    normalise_bins(kept, options, image_name, out);
    return out;
}

}  // namespace roughscope::image::detail
