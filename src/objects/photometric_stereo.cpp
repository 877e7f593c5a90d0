// Photometric stereo (objects/photometric_stereo.hpp, docs/photometric-stereo.md).
#include "roughscope/objects/photometric_stereo.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Dense>

#include "photometric_stereo_rough.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/parallel.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr std::uint8_t kUnusable = kPixelSaturated | kPixelClippedLow | kPixelMissing;
// Light sets are bit masks; up to this many lights every set's inverse is tabulated up front.
constexpr std::size_t kMaxTabulatedLights = 12;
constexpr std::size_t kMaxLights = 32;
constexpr std::size_t kRowsPerBand = 16;

constexpr std::array<NameEntry<PhotometricModel>, 3> kModelNames{{
    {"lambert", PhotometricModel::Lambert},
    {"vh_gaussian", PhotometricModel::VeryRoughGaussian},
    {"vh_exponential", PhotometricModel::VeryRoughExponential},
}};

// The normal equations' inverse (Σ_S L Lᵀ)⁻¹ of a set S, or nothing when its lights are nearly
// coplanar (smallest eigenvalue / largest below kPhotometricStereoMinLightSpread²).
std::optional<Eigen::Matrix3d> subset_inverse(const std::vector<Eigen::Vector3d>& lights,
                                              std::uint32_t set) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    for (std::size_t j = 0; j < lights.size(); ++j)
        if (set & (1U << j)) m += lights[j] * lights[j].transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(m, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d ev = eigen.eigenvalues();  // increasing
    const double spread2 = kPhotometricStereoMinLightSpread * kPhotometricStereoMinLightSpread;
    if (!(ev(2) > 0.0) || ev(0) < spread2 * ev(2)) return std::nullopt;
    return m.inverse();
}

class Solver {
  public:
    explicit Solver(const std::vector<Eigen::Vector3d>& lights) : lights_(lights) {
        if (lights.size() > kMaxTabulatedLights) return;
        table_.resize(std::size_t{1} << lights.size());
        for (std::uint32_t set = 0; set < table_.size(); ++set)
            if (std::popcount(set) >= 3) table_[set] = subset_inverse(lights, set);
    }

    std::optional<Eigen::Matrix3d> inverse(std::uint32_t set) const {
        if (!table_.empty()) return table_[set];
        return subset_inverse(lights_, set);
    }

    const std::vector<Eigen::Vector3d>& lights() const { return lights_; }

  private:
    const std::vector<Eigen::Vector3d>& lights_;
    std::vector<std::optional<Eigen::Matrix3d>> table_;
};

struct PixelSolution {
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    std::uint32_t set = 0;
    int highlights = 0;
    bool solved = false;
};

// g over the set, then highlights left out one at a time (the header's rule).
PixelSolution solve_pixel(const Solver& solver, const double* value, std::uint32_t set,
                          double highlight_fraction) {
    PixelSolution s;
    const auto& lights = solver.lights();
    for (;;) {
        const std::optional<Eigen::Matrix3d> inverse = solver.inverse(set);
        if (!inverse) return s;
        Eigen::Vector3d b = Eigen::Vector3d::Zero();
        for (std::size_t j = 0; j < lights.size(); ++j)
            if (set & (1U << j)) b += value[j] * lights[j];
        s.g = *inverse * b;
        s.set = set;
        s.solved = true;
        if (std::popcount(set) < 4) return s;
        const double rho = s.g.norm();
        int worst = -1;
        double worst_excess = highlight_fraction * rho;
        for (std::size_t j = 0; j < lights.size(); ++j) {
            if (!(set & (1U << j))) continue;
            const double excess = value[j] - s.g.dot(lights[j]);
            if (excess > worst_excess) {
                worst_excess = excess;
                worst = static_cast<int>(j);
            }
        }
        if (worst < 0) return s;
        set &= ~(1U << static_cast<unsigned>(worst));
        ++s.highlights;
    }
}

void check_inputs(const std::vector<const LinearImage*>& images,
                  const std::vector<Eigen::Vector3d>& lights, const std::vector<std::uint8_t>& mask,
                  const PhotometricStereoOptions& options) {
    if (lights.size() < 3 || lights.size() > kMaxLights)
        throw InvalidArgument(concat("photometric stereo: ", std::to_string(lights.size()),
                                     " lights; it needs 3 to ", std::to_string(kMaxLights)));
    if (images.size() != lights.size())
        throw InvalidArgument(concat("photometric stereo: ", std::to_string(images.size()),
                                     " images for ", std::to_string(lights.size()),
                                     " lights; give one image per light"));
    for (std::size_t j = 0; j < lights.size(); ++j) {
        const Eigen::Vector3d& L = lights[j];
        if (!L.allFinite() || std::abs(L.norm() - 1.0) > 1e-6)
            throw InvalidArgument(concat("photometric stereo: light ", std::to_string(j),
                                         " is not a unit vector (|L| must be 1 ± 1e-6)"));
        if (!(L.z() > 0.0))
            throw InvalidArgument(concat("photometric stereo: light ", std::to_string(j),
                                         " has L_z = ", check::format_number(L.z()),
                                         ": it points away from the camera (L_z must be > 0)"));
    }
    Eigen::MatrixXd m(static_cast<Eigen::Index>(lights.size()), 3);
    for (std::size_t j = 0; j < lights.size(); ++j)
        m.row(static_cast<Eigen::Index>(j)) = lights[j].transpose();
    const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::MatrixXd>(m).singularValues();
    if (sv(2) < kPhotometricStereoMinLightSpread * sv(0))
        throw InvalidArgument(
            concat("photometric stereo: the lights are coplanar (smallest singular value of their "
                   "directions ",
                   check::format_number(sv(2) / sv(0)), " of the largest; at least ",
                   check::format_number(kPhotometricStereoMinLightSpread), " needed)"));
    const LinearImage* first = images.front();
    for (std::size_t j = 0; j < images.size(); ++j) {
        const LinearImage* im = images[j];
        if (im == nullptr || im->pixel_count() == 0)
            throw InvalidArgument(
                concat("photometric stereo: image ", std::to_string(j), " is empty"));
        if (im->width != first->width || im->height != first->height)
            throw InvalidArgument(concat(
                "photometric stereo: image ", std::to_string(j), " is ", std::to_string(im->width),
                " × ", std::to_string(im->height), ", image 0 ", std::to_string(first->width),
                " × ", std::to_string(first->height), "; all must be of one size"));
    }
    if (!mask.empty() && mask.size() != first->pixel_count())
        throw InvalidArgument(concat("photometric stereo: the mask has ",
                                     std::to_string(mask.size()), " pixels, the images ",
                                     std::to_string(first->pixel_count())));
    check_photometric_stereo_options(options, lights.size());
}

// The channel average of pixel p of an image.
double pixel_value(const LinearImage& im, std::size_t p) {
    const std::size_t n = im.pixel_count();
    double sum = 0.0;
    for (std::size_t c = 0; c < im.channels; ++c) sum += im.values[c * n + p];
    return sum / static_cast<double>(im.channels);
}

struct BandCounts {
    std::size_t object = 0, valid = 0, too_few = 0, no_solution = 0, highlights = 0,
                rough_better = 0, compared = 0;
};

double median_of_finite(const std::vector<float>& values) {
    std::vector<float> v;
    for (const float x : values)
        if (std::isfinite(x)) v.push_back(x);
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

}  // namespace

std::string_view to_string(PhotometricModel model) { return name_of(kModelNames, model); }

PhotometricModel parse_photometric_model(std::string_view name) {
    return parse_name(kModelNames, "photometric stereo model", name);
}

void check_photometric_stereo_options(const PhotometricStereoOptions& options,
                                      std::size_t num_lights) {
    if (!options.light_intensities.empty()) {
        if (options.light_intensities.size() != num_lights)
            throw InvalidArgument(
                concat("photometric stereo: ", std::to_string(options.light_intensities.size()),
                       " light intensities for ", std::to_string(num_lights), " lights"));
        for (std::size_t j = 0; j < num_lights; ++j) {
            const double e = options.light_intensities[j];
            if (!(e > 0.0 && std::isfinite(e)))
                throw InvalidArgument(concat("photometric stereo: light_intensities[",
                                             std::to_string(j), "] = ", check::format_number(e),
                                             " must be finite and > 0"));
        }
    }
    if (!(options.shadow_fraction >= 0.0 && options.shadow_fraction < 1.0))
        throw InvalidArgument(concat(
            "photometric stereo: shadow_fraction = ", check::format_number(options.shadow_fraction),
            " must be in [0, 1)"));
    if (!(options.min_sigma_over_T > 0.0 && options.min_sigma_over_T < options.max_sigma_over_T &&
          std::isfinite(options.max_sigma_over_T)))
        throw InvalidArgument(concat("photometric stereo: the σ/T range [",
                                     check::format_number(options.min_sigma_over_T), ", ",
                                     check::format_number(options.max_sigma_over_T),
                                     "] must satisfy 0 < min_sigma_over_T < max_sigma_over_T"));
    if (!(options.highlight_fraction > 0.0 && std::isfinite(options.highlight_fraction)))
        throw InvalidArgument(concat("photometric stereo: highlight_fraction = ",
                                     check::format_number(options.highlight_fraction),
                                     " must be finite and > 0"));
}

PhotometricStereoResult photometric_stereo(const std::vector<const LinearImage*>& images,
                                           const std::vector<Eigen::Vector3d>& lights,
                                           const std::vector<std::uint8_t>& mask,
                                           const PhotometricStereoOptions& options) {
    check_inputs(images, lights, mask, options);
    const std::size_t k = lights.size();
    const std::size_t width = images.front()->width;
    const std::size_t height = images.front()->height;
    const std::size_t n = width * height;
    std::vector<double> inv_e(k, 1.0);
    for (std::size_t j = 0; j < options.light_intensities.size(); ++j)
        inv_e[j] = 1.0 / options.light_intensities[j];

    PhotometricStereoResult r;
    r.width = width;
    r.height = height;
    r.normals.assign(3 * n, kNaN);
    r.albedo.assign(n, kNaN);
    r.residual.assign(n, kNaN);
    r.lights_used.assign(n, 0);
    r.model = options.model;
    const bool rough = options.model != PhotometricModel::Lambert;
    if (rough) {
        r.sigma_over_T.assign(n, kNaN);
        r.sigma_over_T_stderr.assign(n, kNaN);
        r.delta_aic.assign(n, kNaN);
    }
    detail::RoughPixelProblem problem;
    problem.lights = &lights;
    problem.correlation = options.model == PhotometricModel::VeryRoughExponential
                              ? Correlation::Exponential
                              : Correlation::Gaussian;
    problem.highlight_fraction = options.highlight_fraction;
    problem.min_sigma_over_T = options.min_sigma_over_T;
    problem.max_sigma_over_T = options.max_sigma_over_T;
    const Solver solver(lights);
    const std::size_t bands = (height + kRowsPerBand - 1) / kRowsPerBand;
    std::vector<BandCounts> counts(bands);
    run_bands(bands, options.threads, [&](std::size_t band) {
        BandCounts& c = counts[band];
        std::vector<double> value(k);
        detail::RoughPixelProblem pixel = problem;
        pixel.value = value.data();
        const std::size_t row_end = std::min(height, (band + 1) * kRowsPerBand);
        for (std::size_t p = band * kRowsPerBand * width; p < row_end * width; ++p) {
            if (!mask.empty() && mask[p] == 0) continue;
            ++c.object;
            double brightest = 0.0;
            std::uint32_t set = 0;
            for (std::size_t j = 0; j < k; ++j) {
                value[j] = pixel_value(*images[j], p) * inv_e[j];
                if ((images[j]->flags[p] & kUnusable) == 0 && std::isfinite(value[j])) {
                    set |= 1U << j;
                    brightest = std::max(brightest, value[j]);
                }
            }
            for (std::size_t j = 0; j < k; ++j)
                if ((set & (1U << j)) && !(value[j] > options.shadow_fraction * brightest))
                    set &= ~(1U << j);
            if (std::popcount(set) < 3) {
                ++c.too_few;
                continue;
            }
            const PixelSolution s =
                solve_pixel(solver, value.data(), set, options.highlight_fraction);
            const double rho = s.g.norm();
            if (!s.solved || !(rho > 0.0) || !(s.g.z() > 0.0)) {
                ++c.no_solution;
                continue;
            }
            Eigen::Vector3d normal = s.g / rho;
            double albedo = rho;
            double sse = 0.0;
            for (std::size_t j = 0; j < k; ++j)
                if (s.set & (1U << j)) sse += std::pow(value[j] - s.g.dot(lights[j]), 2);
            int used = std::popcount(s.set);
            float residual = used > 3 ? static_cast<float>(std::sqrt(sse / used) / rho) : kNaN;
            if (rough) {
                // The rough model on the lights before Lambert's highlight rule (its own rule
                // applies); where it cannot be fitted the Lambertian normal stays.
                pixel.set = set;
                pixel.start_normal = normal;
                const detail::RoughPixelFit f = detail::fit_rough_pixel(pixel);
                if (f.ok && f.normal.z() > 0.0) {
                    normal = f.normal;
                    albedo = f.albedo;
                    used = std::popcount(f.set);
                    residual = static_cast<float>(f.residual_rel);
                    r.sigma_over_T[p] = static_cast<float>(f.sigma_over_T);
                    r.sigma_over_T_stderr[p] = static_cast<float>(f.sigma_over_T_stderr);
                    r.delta_aic[p] = static_cast<float>(f.delta_aic);
                    c.highlights += static_cast<std::size_t>(f.highlights);
                    if (std::isfinite(f.delta_aic)) {
                        ++c.compared;
                        if (f.delta_aic > 0.0) ++c.rough_better;
                    }
                }
            }
            for (int a = 0; a < 3; ++a) r.normals[3 * p + a] = static_cast<float>(normal(a));
            r.albedo[p] = static_cast<float>(albedo);
            r.residual[p] = residual;
            r.lights_used[p] = static_cast<std::uint8_t>(used);
            ++c.valid;
            c.highlights += static_cast<std::size_t>(s.highlights);
        }
    });
    for (const BandCounts& c : counts) {
        r.object_pixels += c.object;
        r.valid_pixels += c.valid;
        r.too_few_lights += c.too_few;
        r.no_solution += c.no_solution;
        r.highlights_removed += c.highlights;
        r.rough_better_pixels += c.rough_better;
        r.compared_pixels += c.compared;
    }
    r.median_residual = median_of_finite(r.residual);
    r.median_sigma_over_T = rough ? median_of_finite(r.sigma_over_T) : kNaN;
    r.median_delta_aic = rough ? median_of_finite(r.delta_aic) : kNaN;
    if (r.object_pixels > 0 && r.valid_pixels < r.object_pixels / 2)
        r.warnings.push_back(concat(
            "only ", std::to_string(r.valid_pixels), " of ", std::to_string(r.object_pixels),
            mask.empty() ? " pixels (no mask: the whole image)" : " object pixels",
            " have a normal (", std::to_string(r.too_few_lights),
            " are lit by fewer than 3 usable lights)",
            mask.empty() ? "; give the object's mask (a capture file's roi) to leave out the "
                           "background"
                         : ""));
    return r;
}

}  // namespace roughscope::image
