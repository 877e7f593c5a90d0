#include "roughscope/image/cylinder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include "object_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

constexpr double kSubBinsPerPx = 8.0;     // resolution of the distribution across the axis
constexpr std::size_t kNodesPerBin = 32;  // geometry nodes of a bin's model average
// Floor of a bin's standard error, in units of the profile's maximum: a quantisation step of a
// 14-bit camera (noise-free synthetic data have none of their own).
constexpr double kMinRelativeStandardError = 1e-4;

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

// Per-bin accumulators of the single pass.
struct BinSums {
    double sum = 0, sum2 = 0, diff2 = 0;
    std::size_t count = 0, diffs = 0, flagged = 0;
};

}  // namespace

std::string_view to_string(CylinderHalf half) {
    switch (half) {
        case CylinderHalf::Right:
            return "right";
        case CylinderHalf::Left:
            return "left";
        case CylinderHalf::Both:
            return "both";
    }
    return "right";
}

CylinderHalf parse_cylinder_half(std::string_view name) {
    if (name == "right") return CylinderHalf::Right;
    if (name == "left") return CylinderHalf::Left;
    if (name == "both") return CylinderHalf::Both;
    throw InvalidArgument(
        concat("unknown cylinder half ", quote_input(name), " (valid: right, left, both)"));
}

std::string_view to_string(ProfileModel model) {
    switch (model) {
        case ProfileModel::Lambert:
            return "lambert";
        case ProfileModel::BkGaussian:
            return "bk_gaussian";
        case ProfileModel::VhGaussian:
            return "vh_gaussian";
        case ProfileModel::VhExponential:
            return "vh_exponential";
    }
    return "lambert";
}

std::string_view display_name(ProfileModel model) {
    switch (model) {
        case ProfileModel::Lambert:
            return "Lambert";
        case ProfileModel::BkGaussian:
            return "Eq. 7 B–K(G)";
        case ProfileModel::VhGaussian:
            return "Eq. 9 V–H–B–K(G)";
        case ProfileModel::VhExponential:
            return "Eq. 10 V–H–B–K(E)";
    }
    return "Lambert";
}

ProfileModel parse_profile_model(std::string_view name) {
    for (const ProfileModel m : kProfileModels)
        if (name == to_string(m)) return m;
    throw InvalidArgument(concat("unknown profile model ", quote_input(name),
                                 " (valid: lambert, bk_gaussian, vh_gaussian, vh_exponential)"));
}

double profile_model_brightness(ProfileModel model, const Geometry& geom, double sigma_over_T,
                                Radiometry radiometry) {
    switch (model) {
        case ProfileModel::Lambert:  // Lambert's law: E ∝ cos θi
            check::geometry(geom);
            return std::cos(geom.theta_i_rad);
        case ProfileModel::BkGaussian:  // Eq. 7 (general form Eq. 4, F_Beck)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Gaussian,
                                         GeometricFactor::Beckmann, radiometry);
        case ProfileModel::VhGaussian:  // Eq. 9 (general form Eq. 4, F_VH)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Gaussian,
                                         GeometricFactor::VernoldHarvey, radiometry);
        case ProfileModel::VhExponential:  // Eq. 10 (general form Eq. 5, F_VH)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Exponential,
                                         GeometricFactor::VernoldHarvey, radiometry);
    }
    return 0.0;
}

const ProfileModelCurve& CylinderProfile::curve(ProfileModel model) const {
    for (const ProfileModelCurve& c : models)
        if (c.model == model) return c;
    throw InvalidArgument(concat("the profile has no curve ", to_string(model)));
}

void check_cylinder_options(const CylinderOptions& options) {
    detail::check_unit_direction("cylinder light", options.light);
    detail::check_unit_direction("cylinder view", options.view);
    if (!(options.bin_width_deg > 0.0 && options.bin_width_deg <= 45.0))
        throw InvalidArgument(
            concat("cylinder bin_width_deg = ", format_number(options.bin_width_deg),
                   " is outside the valid range (0, 45] deg"));
    if (options.min_pixels_per_bin < 1)
        throw InvalidArgument("cylinder min_pixels_per_bin must be at least 1");
    if (!(options.limb_fraction > 0.0 && options.limb_fraction <= 1.0))
        throw InvalidArgument(
            concat("cylinder limb_fraction = ", format_number(options.limb_fraction),
                   " is outside the valid range (0, 1]"));
    if (options.sigma_over_T) check::positive("cylinder sigma_over_T", *options.sigma_over_T);
    if (!(options.fit_max_theta_i_deg > 0.0 && options.fit_max_theta_i_deg < 90.0))
        throw InvalidArgument(
            concat("cylinder fit_max_theta_i_deg = ", format_number(options.fit_max_theta_i_deg),
                   " is outside the valid range (0, 90) deg"));
    if (!(options.fit_max_flagged_fraction >= 0.0 && options.fit_max_flagged_fraction <= 1.0))
        throw InvalidArgument(concat(
            "cylinder fit_max_flagged_fraction = ", format_number(options.fit_max_flagged_fraction),
            " is outside the valid range [0, 1]"));
    check::positive("cylinder departure_k", options.departure_k);
    if (options.departure_bins < 1)
        throw InvalidArgument("cylinder departure_bins must be at least 1");
    if (options.axis) {
        const CylinderAxis& a = *options.axis;
        (void)cylinder_axis_from_line(a.point_x_px, a.point_y_px, a.direction_x, a.direction_y,
                                      a.radius_px);
    }
}

// The dark-limb warning's factor (measure_cylinder_profile).
constexpr double kDarkLimbFactor = 10.0;

CylinderProfile measure_cylinder_profile(const LinearImage& image,
                                         const std::vector<std::uint8_t>* region_mask,
                                         const CylinderOptions& options) {
    check_cylinder_options(options);
    check_linear_image(image);
    const std::size_t w = image.width, h = image.height;
    if (region_mask && region_mask->size() != image.pixel_count())
        throw InvalidArgument(concat("cylinder region mask has ",
                                     std::to_string(region_mask->size()), " entries, the image ",
                                     image_name(image), " has ",
                                     std::to_string(image.pixel_count()), " pixels"));

    CylinderProfile out;
    out.light = options.light;
    out.view = options.view;
    out.half = options.half;
    out.bin_width_rad = deg_to_rad(options.bin_width_deg);

    // The axis, and the object mask when it comes from the silhouette.
    std::vector<std::uint8_t> object;
    double silhouette_level = 0.0;
    if (options.axis) {
        out.axis = cylinder_axis_from_line(options.axis->point_x_px, options.axis->point_y_px,
                                           options.axis->direction_x, options.axis->direction_y,
                                           options.axis->radius_px);
    } else {
        Silhouette s = detail::find_silhouette_of_checked_image(image, options.silhouette);
        out.axis = fit_cylinder_axis(s, options.axis_fit);
        silhouette_level = s.threshold;
        object = std::move(s.mask);
    }
    const CylinderAxis& axis = out.axis;
    const double R = axis.radius_px;
    const double ux = axis.across_x(), uy = axis.across_y();
    const double ax = axis.direction_x, ay = axis.direction_y;

    // Sub-bins of the distance across the axis (1/8 px) and their bin.
    const double bw = out.bin_width_rad;
    const bool both = options.half == CylinderHalf::Both;
    const auto n_bins = static_cast<std::size_t>(std::ceil((both ? kPi : kPi / 2.0) / bw - 1e-9));
    const auto n_sub = static_cast<std::size_t>(std::ceil(2.0 * R * kSubBinsPerPx)) + 1;
    // Bin of the normal angle α (x: α, −α or α + π/2 by the half); −1 outside the half or the
    // limb.
    const auto bin_of = [&](double d) -> std::int32_t {
        if (std::abs(d) > options.limb_fraction * R) return -1;
        const double alpha = std::asin(std::clamp(d / R, -1.0, 1.0));
        double x = 0;
        switch (options.half) {
            case CylinderHalf::Right:
                x = alpha;
                break;
            case CylinderHalf::Left:
                x = -alpha;
                break;
            case CylinderHalf::Both:
                x = alpha + kPi / 2.0;
                break;
        }
        if (x < 0) return -1;
        return static_cast<std::int32_t>(std::min(n_bins - 1, static_cast<std::size_t>(x / bw)));
    };
    // Each sub-bin holds at most one bin edge (bins are ≥ 1/8 px wide only when R sin(bw) ≥ 1/8,
    // which every R ≥ 4 px and bw ≥ 2° meet; narrower bins share a sub-bin and the finer edge is
    // missed): the pixel's side of that edge, split[k], picks the half-sub-bin 2k or 2k + 1.
    std::vector<double> split(n_sub, std::numeric_limits<double>::infinity());
    std::vector<std::int32_t> sub_bin(2 * n_sub, -1);
    for (std::size_t k = 0; k < n_sub; ++k) {
        const double d_lo = static_cast<double>(k) / kSubBinsPerPx - R;
        const double d_hi = d_lo + 1.0 / kSubBinsPerPx;
        const std::int32_t b_lo = bin_of(d_lo), b_hi = bin_of(d_hi);
        sub_bin[2 * k] = b_lo;
        sub_bin[2 * k + 1] = b_lo;
        if (b_lo != b_hi) {  // bisect for the edge
            double a = d_lo, b = d_hi;
            for (int it = 0; it < 60; ++it) {
                const double m = 0.5 * (a + b);
                (bin_of(m) == b_lo ? a : b) = m;
            }
            split[k] = b;
            sub_bin[2 * k + 1] = b_hi;
        }
    }

    // Slices (1 px) along the axis: t = (p − P)·a over the image's corners.
    double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
    for (const double cx : {0.0, static_cast<double>(w)})
        for (const double cy : {0.0, static_cast<double>(h)}) {
            const double t = (cx - axis.point_x_px) * ax + (cy - axis.point_y_px) * ay;
            t_min = std::min(t_min, t);
            t_max = std::max(t_max, t);
        }
    const auto n_slices = static_cast<std::size_t>(std::ceil(t_max - t_min)) + 1;

    std::vector<BinSums> bins(n_bins);
    std::vector<double> slice_sum(n_bins * n_slices, 0.0);
    std::vector<std::uint32_t> slice_count(n_bins * n_slices, 0);
    std::vector<std::uint32_t> sub_count(2 * n_sub, 0);
    std::vector<double> sub_d(2 * n_sub, 0.0);

    // The single pass. Noise from differences with the previous pixel along the axis' closer
    // image direction (previous row for a steep axis, previous column otherwise), same bin.
    const bool rows_along_axis = std::abs(ay) >= std::abs(ax);
    std::vector<float> prev_value(w, 0.0F);
    std::vector<std::int32_t> prev_bin(w, -1);
    const float* p0 = image.plane(0);
    const float* p1 = image.channels == 3 ? image.plane(1) : nullptr;
    const float* p2 = image.channels == 3 ? image.plane(2) : nullptr;
    const std::uint8_t* reg = region_mask ? region_mask->data() : nullptr;
    const std::uint8_t* obj = object.empty() ? nullptr : object.data();
    const double sub_offset = R * kSubBinsPerPx;
    for (std::size_t r = 0; r < h; ++r) {
        const double yc = static_cast<double>(r) + 0.5 - axis.point_y_px;
        const double xc0 = 0.5 - axis.point_x_px;
        const double d0 = xc0 * ux + yc * uy;
        const double t0 = xc0 * ax + yc * ay - t_min;
        float left_value = 0.0F;
        std::int32_t left_bin = -1;
        const std::size_t row = r * w;
        for (std::size_t c = 0; c < w; ++c) {
            const std::size_t i = row + c;
            std::int32_t b = -1;
            const double d = d0 + static_cast<double>(c) * ux;
            const double sf = d * kSubBinsPerPx + sub_offset;
            if (sf >= 0.0 && sf < static_cast<double>(n_sub) && (!reg || reg[i]) &&
                (!obj || obj[i])) {
                const auto k = static_cast<std::size_t>(sf);
                const std::size_t sk = 2 * k + (d >= split[k] ? 1 : 0);
                b = sub_bin[sk];
                if (b >= 0 && image.flags[i] != 0) {
                    ++out.pixels_flagged;
                    ++bins[static_cast<std::size_t>(b)].flagged;
                    b = -1;
                }
                if (b >= 0) {
                    float v = p0[i];
                    if (p1) v = (v + p1[i] + p2[i]) * (1.0F / 3.0F);
                    const double vd = v;
                    BinSums& bs = bins[static_cast<std::size_t>(b)];
                    bs.sum += vd;
                    bs.sum2 += vd * vd;
                    ++bs.count;
                    ++sub_count[sk];
                    sub_d[sk] += d;
                    const auto sl =
                        static_cast<std::size_t>(std::max(0.0, t0 + static_cast<double>(c) * ax));
                    const std::size_t si =
                        static_cast<std::size_t>(b) * n_slices + std::min(sl, n_slices - 1);
                    slice_sum[si] += vd;
                    ++slice_count[si];
                    const std::int32_t nb = rows_along_axis ? prev_bin[c] : left_bin;
                    if (nb == b) {
                        const double diff = vd - (rows_along_axis ? prev_value[c] : left_value);
                        bs.diff2 += diff * diff;
                        ++bs.diffs;
                    }
                    left_value = v;
                    prev_value[c] = v;
                }
            }
            left_bin = b;
            prev_bin[c] = b;
        }
    }

    // Bins: mean, standard errors, geometry nodes.
    struct Work {
        ProfileBin bin;
        std::vector<detail::ProfileNode> nodes;
    };
    std::vector<Work> kept;
    std::size_t dropped_small = 0, dropped_dark = 0;
    for (std::size_t b = 0; b < n_bins; ++b) {
        const BinSums& bs = bins[b];
        out.pixels_used += bs.count;
        if (bs.count == 0) continue;
        if (bs.count < options.min_pixels_per_bin) {
            ++dropped_small;
            continue;
        }
        Work wk;
        ProfileBin& pb = wk.bin;
        const auto n = static_cast<double>(bs.count);
        pb.count = bs.count;
        pb.flagged = bs.flagged;
        pb.raw_mean = bs.sum / n;
        const double var =
            bs.count > 1 ? std::max(0.0, (bs.sum2 - n * pb.raw_mean * pb.raw_mean) / (n - 1.0))
                         : 0.0;
        const double noise_var =
            bs.diffs >= 2 ? bs.diff2 / (2.0 * static_cast<double>(bs.diffs)) : var;
        pb.stderr_pixel = std::sqrt(noise_var / n);
        double s2 = 0;
        std::size_t J = 0;
        for (std::size_t j = 0; j < n_slices; ++j) {
            const std::uint32_t nj = slice_count[b * n_slices + j];
            if (nj == 0) continue;
            ++J;
            const double e = slice_sum[b * n_slices + j] - static_cast<double>(nj) * pb.raw_mean;
            s2 += e * e;  // n_j² (m_j − m)²
        }
        pb.slices = J;
        pb.stderr_slices =
            J >= 2 ? std::sqrt(s2 * static_cast<double>(J) / static_cast<double>(J - 1)) / n : 0.0;
        // Nodes: the bin's sub-bins grouped into at most kNodesPerBin runs (count, mean d).
        std::vector<std::size_t> subs;
        for (std::size_t k = 0; k < 2 * n_sub; ++k)
            if (sub_bin[k] == static_cast<std::int32_t>(b) && sub_count[k] > 0) subs.push_back(k);
        const std::size_t group = (subs.size() + kNodesPerBin - 1) / kNodesPerBin;
        double dsum = 0;
        for (std::size_t g = 0; g < subs.size(); g += group) {
            double cnt = 0, ds = 0;
            for (std::size_t k = g; k < std::min(subs.size(), g + group); ++k) {
                cnt += sub_count[subs[k]];
                ds += sub_d[subs[k]];
            }
            dsum += ds;
            wk.nodes.push_back(
                detail::cylinder_node(ds / cnt / R, cnt / n, ux, uy, options.light, options.view));
        }
        pb.across_px = dsum / n;
        pb.alpha_rad = std::asin(std::clamp(pb.across_px / R, -1.0, 1.0));
        const detail::ProfileNode centre =
            detail::cylinder_node(pb.across_px / R, 1.0, ux, uy, options.light, options.view);
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
    if (out.pixels_flagged)
        out.warnings.push_back(concat(std::to_string(out.pixels_flagged),
                                      " flagged pixel(s) (saturated, clipped) left out"));
    if (kept.size() < 3)
        throw DataError(concat(image_name(image), ": the cylinder profile has ",
                               std::to_string(kept.size()), " bin(s) with at least ",
                               std::to_string(options.min_pixels_per_bin),
                               " usable pixels; at least 3 are needed"));
    std::stable_sort(kept.begin(), kept.end(), [&](const Work& x, const Work& y) {
        return both ? x.bin.alpha_rad < y.bin.alpha_rad : x.bin.theta_i_rad < y.bin.theta_i_rad;
    });
    if (both)  // the departure rule and plots run over increasing θi
        std::stable_sort(kept.begin(), kept.end(), [](const Work& x, const Work& y) {
            return x.bin.theta_i_rad < y.bin.theta_i_rad;
        });

    // Normalise by the maximum (§2); the standard errors by the same factor.
    for (const Work& wk : kept) out.maximum = std::max(out.maximum, wk.bin.raw_mean);
    if (!(out.maximum > 0))
        throw DataError(
            concat(image_name(image), ": the cylinder profile has no positive brightness"));
    std::vector<std::vector<detail::ProfileNode>> nodes;
    for (Work& wk : kept) {
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
        nodes.push_back(std::move(wk.nodes));
    }

    // Fits.
    out.gaussian_fit = detail::fit_profile(out.bins, nodes, Correlation::Gaussian, options.factor,
                                           options.radiometry);
    out.exponential_fit = detail::fit_profile(out.bins, nodes, Correlation::Exponential,
                                              options.factor, options.radiometry);
    if (out.gaussian_fit.sigma_over_T && out.exponential_fit.sigma_over_T)
        out.preferred = out.exponential_fit.aic < out.gaussian_fit.aic ? Correlation::Exponential
                                                                       : Correlation::Gaussian;
    else if (out.exponential_fit.sigma_over_T)
        out.preferred = Correlation::Exponential;

    // Model curves.
    for (const ProfileModel m : kProfileModels) {
        ProfileModelCurve curve;
        curve.model = m;
        curve.name = std::string(to_string(m));
        if (m != ProfileModel::Lambert) {
            if (options.sigma_over_T)
                curve.sigma_over_T = options.sigma_over_T;
            else
                curve.sigma_over_T = m == ProfileModel::VhExponential
                                         ? out.exponential_fit.sigma_over_T
                                         : out.gaussian_fit.sigma_over_T;
            if (!curve.sigma_over_T) {
                out.warnings.push_back(
                    concat("no ", to_string(m), " curve: the fit of its σ/T did not succeed"));
                out.models.push_back(std::move(curve));
                continue;
            }
        }
        const double s = curve.sigma_over_T.value_or(1.0);
        curve.prediction = detail::bin_model_averages(nodes, [&](const Geometry& g) {
            return profile_model_brightness(m, g, s, options.radiometry);
        });
        const double mx = *std::max_element(curve.prediction.begin(), curve.prediction.end());
        double ss = 0;
        for (std::size_t b = 0; b < out.bins.size(); ++b) {
            curve.prediction[b] = mx > 0 ? curve.prediction[b] / mx : 0.0;
            const double e = curve.prediction[b] - out.bins[b].brightness;
            ss += e * e;
        }
        curve.rms_difference = std::sqrt(ss / static_cast<double>(out.bins.size()));
        curve.departure_bin = detail::departure_bin(out.bins, curve.prediction, options.departure_k,
                                                    options.departure_bins);
        if (curve.departure_bin)
            curve.departure_theta_i_rad = out.bins[*curve.departure_bin].theta_i_rad;
        out.models.push_back(std::move(curve));
    }
    if (const auto& s = out.curve(ProfileModel::VhGaussian).sigma_over_T)
        out.theta_K_rad = caron_theta_K_rad(*s);
    // A detected axis takes the silhouette's edge for the limb. On an object whose brightness
    // fades smoothly to the silhouette's level (a narrow very-rough lobe lit from near the
    // camera) the edge lies inside the true limb, and the radius, hence every angle, is off; a
    // limb that stays bright to the edge (Lambert: cos 80° = 0.17) is found where it is. The
    // sign: the profile 10° inside the detected limb is within a few times the silhouette's
    // level.
    if (axis.detected && out.maximum > 0.0 && !out.bins.empty()) {
        // The bin nearest 80° (or the outermost one, when the profile stops short of 80°).
        const double level = silhouette_level / out.maximum;
        const double target = deg_to_rad(80.0);
        const auto distance = [&](const ProfileBin& b) {
            return std::abs(std::min(std::abs(b.alpha_rad), target) - target) -
                   1e-3 * std::abs(b.alpha_rad);
        };
        const ProfileBin* near = &out.bins.front();
        for (const ProfileBin& b : out.bins)
            if (distance(b) < distance(*near)) near = &b;
        if (std::abs(near->alpha_rad) >= deg_to_rad(60.0) &&
            near->brightness < kDarkLimbFactor * level)
            out.warnings.push_back(concat(
                "the profile at ", check::format_number(rad_to_deg(std::abs(near->alpha_rad))),
                "° from the axis (", check::format_number(near->brightness),
                " of the maximum) is within ", check::format_number(kDarkLimbFactor),
                "x the silhouette's level (", check::format_number(level),
                "): the limb is dark, the detected edge is likely inside the true limb, so the "
                "radius and the angles are biased; give the axis (or edges) of the cylinder"));
    }
    return out;
}

}  // namespace roughscope::image

namespace roughscope::image::detail {

void check_unit_direction(std::string_view name, const Eigen::Vector3d& v) {
    if (!v.allFinite() || std::abs(v.norm() - 1.0) > 1e-6)
        throw InvalidArgument(concat(name, " direction (", check::format_number(v.x()), ", ",
                                     check::format_number(v.y()), ", ", check::format_number(v.z()),
                                     ") must be a finite unit vector (camera frame)"));
    if (!(v.z() > 0.0))
        throw InvalidArgument(concat(name, " direction (", check::format_number(v.x()), ", ",
                                     check::format_number(v.y()), ", ", check::format_number(v.z()),
                                     ") must point towards the camera's side (z > 0): it is "
                                     "below the horizon of every visible surface point"));
}

ProfileNode cylinder_node(double s, double weight, double ux, double uy,
                          const Eigen::Vector3d& light, const Eigen::Vector3d& view) {
    s = std::clamp(s, -1.0, 1.0);
    const Eigen::Vector3d n(s * ux, -s * uy, std::sqrt(std::max(0.0, 1.0 - s * s)));
    ProfileNode node;
    node.weight = weight;
    if (const auto g = geometry_from_vectors(n.normalized(), light, view)) {
        node.geometry = *g;
        node.lit = true;
    }
    return node;
}

ProfileFit fit_profile(const std::vector<ProfileBin>& bins,
                       const std::vector<std::vector<ProfileNode>>& nodes, Correlation correlation,
                       GeometricFactor factor, Radiometry radiometry) {
    ProfileFit fit;
    fit.correlation = correlation;
    std::vector<std::size_t> used;
    LeastSquaresProblem problem;
    for (std::size_t b = 0; b < bins.size(); ++b) {
        if (!bins[b].in_fit) continue;
        used.push_back(b);
        problem.data.push_back(bins[b].brightness);
        problem.weights.push_back(1.0 / (bins[b].standard_error * bins[b].standard_error));
    }
    fit.bins = static_cast<int>(used.size());
    if (used.size() < 3) {
        fit.status = SolverStatus::NotIdentifiable;
        fit.message = concat(std::to_string(used.size()),
                             " bin(s) in the fit range; σ/T and the gain need at least 3");
        return fit;
    }
    ParameterSpec p;
    p.name = "sigma_over_T";
    p.lower = 1e-3;
    p.upper = 1e3;
    problem.parameters = {p};
    problem.residual = ResidualType::Absolute;
    problem.gain = GainMode::Profiled;
    problem.model = [&](std::span<const double> theta, std::span<double> out) {
        const double s = theta[0];
        for (std::size_t k = 0; k < used.size(); ++k) {
            double m = 0;
            for (const ProfileNode& n : nodes[used[k]])
                if (n.lit)
                    m += n.weight *
                         very_rough_brightness(n.geometry, s, correlation, factor, radiometry);
            if (!std::isfinite(m)) return false;
            out[k] = m;
        }
        return true;
    };
    const LeastSquaresResult r = solve_least_squares(problem);
    fit.status = r.status;
    fit.message = r.message;
    fit.aic = r.aic;
    fit.gain = r.gain;
    const FitParameter& sp = r.parameter("sigma_over_T");
    if (sp.identified && r.status != SolverStatus::Failed &&
        r.status != SolverStatus::NotIdentifiable) {
        fit.sigma_over_T = sp.value;
        if (r.covariance_available && !sp.at_bound) fit.sigma_over_T_stderr = sp.std_error;
    }
    return fit;
}

std::optional<std::size_t> departure_bin(const std::vector<ProfileBin>& bins,
                                         const std::vector<double>& prediction, double k,
                                         std::size_t run) {
    const std::size_t n = bins.size();
    auto off = [&](std::size_t b) {
        return std::abs(prediction[b] - bins[b].brightness) > k * bins[b].standard_error;
    };
    for (std::size_t b = 0; b < n; ++b) {
        const std::size_t end = std::min(n, b + run);
        bool all = true;
        for (std::size_t j = b; j < end && all; ++j) all = off(j);
        if (all) return b;
    }
    return std::nullopt;
}

}  // namespace roughscope::image::detail
