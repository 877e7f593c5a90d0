// Synthetic camera captures (simulation/capture.hpp): scene geometry, per-pixel brightness from
// the library's models, and the camera (shot noise, read noise, full well, gain, black level,
// clipping, response, quantisation). Formulas: docs/simulation-captures.md.
#include "roughscope/simulation/capture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/poisson_distribution.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

// GCC 12 cannot see that boost::random::poisson_distribution initialises the union member of the
// branch (PTRD or inversion) its mean selects, and warns falsely when the distribution is kept
// between draws (as here, to reuse it for equal means).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace roughscope::simulation {

namespace {

constexpr std::array<NameEntry<SceneShape>, 3> kShapeNames{{
    {"plane", SceneShape::Plane},
    {"cylinder", SceneShape::Cylinder},
    {"sphere", SceneShape::Sphere},
}};

constexpr std::array<NameEntry<BrightnessModel>, 8> kModelNames{{
    {"very_rough", BrightnessModel::VeryRough},
    {"mean_scattered_power", BrightnessModel::MeanScatteredPower},
    {"lambert", BrightnessModel::Lambert},
    {"oren_nayar", BrightnessModel::OrenNayar},
    {"lafortune", BrightnessModel::Lafortune},
    {"tabulated", BrightnessModel::Tabulated},
    {"beckmann_kirchhoff", BrightnessModel::MeanScatteredPower},
    {"table", BrightnessModel::Tabulated},
}};

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string number_text(double value) { return format_message(value); }

void check_unit(std::string_view name, const Eigen::Vector3d& v) {
    if (!v.allFinite() || std::abs(v.norm() - 1.0) > 1e-6)
        throw InvalidArgument(concat(name, " must be a finite unit vector (|", name,
                                     "| = 1 within 1e-6); got (", number_text(v.x()), ", ",
                                     number_text(v.y()), ", ", number_text(v.z()), ")"));
}

// splitmix64: a well-mixed 64-bit value from a counter (the per-row seeds).
std::uint64_t splitmix64(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
}

// Exact Poisson sampling by inversion for a mean that repeats along a row (a plane, the
// background, flat regions): the probabilities p(k) = e^{−μ} μ^k / k! on
// [μ − 13√μ − 1, μ + 13√μ + 1] (outside it the mass is < 1e−37) by the recurrence
// p(k+1) = p(k) μ/(k+1) from lgamma at the first k, their cumulative sum normalised, and a guide
// table for the search (docs/simulation-captures.md, "Camera").
class PoissonTable {
  public:
    static constexpr double kMinMean = 10.0;  // below: Boost's inversion is as fast
    static constexpr double kMaxMean = 1e7;   // above: the table would be large

    double mean() const { return mean_; }

    void build(double mu) {
        mean_ = mu;
        const double spread = 13.0 * std::sqrt(mu) + 1.0;
        first_ = static_cast<std::int64_t>(std::max(0.0, std::floor(mu - spread)));
        const auto last = static_cast<std::int64_t>(std::ceil(mu + spread));
        cdf_.resize(static_cast<std::size_t>(last - first_ + 1));
        const auto k0 = static_cast<double>(first_);
        double p = std::exp(k0 * std::log(mu) - mu - std::lgamma(k0 + 1.0));
        double sum = 0.0;
        for (std::size_t j = 0; j < cdf_.size(); ++j) {
            sum += p;
            cdf_[j] = sum;
            p *= mu / (k0 + static_cast<double>(j) + 1.0);
        }
        for (double& c : cdf_) c /= sum;
        cdf_.back() = 1.0;
        guide_.resize(cdf_.size());
        std::size_t j = 0;
        for (std::size_t g = 0; g < guide_.size(); ++g) {
            const double u = static_cast<double>(g) / static_cast<double>(guide_.size());
            while (cdf_[j] < u) ++j;
            guide_[g] = static_cast<std::uint32_t>(j);
        }
    }

    template <class Engine>
    std::int64_t operator()(Engine& engine) const {
        const double u = static_cast<double>(engine() >> 11) * 0x1.0p-53;  // [0, 1)
        std::size_t j = guide_[static_cast<std::size_t>(u * static_cast<double>(guide_.size()))];
        while (cdf_[j] <= u) ++j;
        return first_ + static_cast<std::int64_t>(j);
    }

  private:
    double mean_ = -1.0;
    std::int64_t first_ = 0;
    std::vector<double> cdf_;
    std::vector<std::uint32_t> guide_;
};

// The surface normal seen through image-plane point p (std::nullopt: the ray misses).
std::optional<Eigen::Vector3d> surface_normal(SceneShape shape, const Eigen::Vector3d& p,
                                              const Eigen::Vector3d& view, double radius) {
    // In units of the radius (q = p / R), so that no length under- or overflows.
    switch (shape) {
        case SceneShape::Plane:
            return Eigen::Vector3d::UnitZ();
        case SceneShape::Sphere: {
            const Eigen::Vector3d q = p / radius;
            const double h2 = 1.0 - q.squaredNorm();
            if (!(h2 >= 0.0)) return std::nullopt;
            return (q + std::sqrt(h2) * view).normalized();
        }
        case SceneShape::Cylinder: {
            // |q⊥ + t V⊥|² = 1 with ⊥ = the components across the Y axis; the larger root is the
            // side facing the camera.
            const Eigen::Vector3d q_perp(p.x() / radius, 0.0, p.z() / radius);
            const Eigen::Vector3d v_perp(view.x(), 0.0, view.z());
            const double a = v_perp.squaredNorm();
            const double b = 2.0 * q_perp.dot(v_perp);
            const double c = q_perp.squaredNorm() - 1.0;
            const double disc = b * b - 4.0 * a * c;
            if (!(disc >= 0.0)) return std::nullopt;
            const double t = (-b + std::sqrt(disc)) / (2.0 * a);
            return (q_perp + t * v_perp).normalized();
        }
    }
    return std::nullopt;
}

double encode_response(const CameraModel& camera, double u) {
    switch (camera.response) {
        case Response::Linear:
            return u;
        case Response::Srgb:
            return srgb_encode(u);
        case Response::Gamma:
            return u <= 0.0 ? 0.0 : std::pow(u, 1.0 / camera.gamma);
    }
    return u;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Names

std::string_view to_string(SceneShape shape) { return name_of(kShapeNames, shape); }
SceneShape parse_scene_shape(std::string_view name) {
    return parse_name(kShapeNames, "scene shape", name);
}
std::string_view to_string(BrightnessModel model) { return name_of(kModelNames, model); }
BrightnessModel parse_brightness_model(std::string_view name) {
    return parse_name(kModelNames, "brightness model", name);
}

// ---------------------------------------------------------------------------------------------
// Scene, truth, camera

Eigen::Vector3d direction_from_angles(double theta_rad, double phi_rad) {
    return {std::sin(theta_rad) * std::cos(phi_rad), std::sin(theta_rad) * std::sin(phi_rad),
            std::cos(theta_rad)};
}

CameraAxes camera_axes(const Eigen::Vector3d& view) {
    const Eigen::Vector3d forward = -view;
    const bool near_y = std::abs(view.y()) > std::cos(deg_to_rad(0.1));
    const Eigen::Vector3d up_hint = near_y ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    CameraAxes axes;
    axes.right = forward.cross(up_hint).normalized();
    axes.up = axes.right.cross(forward).normalized();
    return axes;
}

double scene_radius_um(const Scene& scene) {
    if (scene.radius_um > 0.0) return scene.radius_um;
    return 0.4 * static_cast<double>(std::min(scene.width, scene.height)) * scene.pixel_size_um;
}

void check_scene(const Scene& scene) {
    if (scene.width < 1 || scene.width > 65535)
        throw InvalidArgument(concat("width = ", std::to_string(scene.width),
                                     " pixels is outside the valid range [1, 65535]"));
    if (scene.height < 1 || scene.height > 65535)
        throw InvalidArgument(concat("height = ", std::to_string(scene.height),
                                     " pixels is outside the valid range [1, 65535]"));
    if (scene.width * scene.height > kMaxCapturePixels)
        throw InvalidArgument(concat("width x height = ", std::to_string(scene.width), " x ",
                                     std::to_string(scene.height),
                                     " pixels is more than the valid maximum of 2^28 pixels"));
    if (!(scene.pixel_size_um >= 1e-9 && scene.pixel_size_um <= 1e12))
        throw InvalidArgument(concat("pixel_size_um = ", number_text(scene.pixel_size_um),
                                     " um is outside the valid range [1e-9, 1e12] um"));
    if (!(scene.radius_um >= 0.0 && scene.radius_um <= 1e15))
        throw InvalidArgument(concat("radius_um = ", number_text(scene.radius_um),
                                     " um is outside the valid range [0, 1e15] um"));
    if (!(scene.background_radiance >= 0.0 && scene.background_radiance <= 1e30))
        throw InvalidArgument(
            concat("background_radiance = ", number_text(scene.background_radiance),
                   " is outside the valid range [0, 1e30]"));
    check_unit("light", scene.light);
    check_unit("view", scene.view);
    if (scene.shape == SceneShape::Plane && scene.view.z() <= 1e-12)
        throw InvalidArgument(
            concat("view: a plane is seen only from above (view z > 0, theta_v in "
                   "[0, 90) deg); got view z = ",
                   number_text(scene.view.z())));
    if (scene.shape == SceneShape::Cylinder && std::abs(scene.view.y()) > std::cos(deg_to_rad(1.0)))
        throw InvalidArgument(
            "view: the cylinder's axis is the scene Y axis; a view within 1 deg of it sees only "
            "its end (choose a view at least 1 deg away from +-Y)");
}

double CameraModel::white_level_dn() const { return std::ldexp(1.0, bit_depth) - 1.0; }

void check_camera(const CameraModel& camera) {
    check::positive("electrons_per_unit_s", camera.electrons_per_unit_s);
    check::positive("exposure_s", camera.exposure_s, "s");
    check::positive("gain_dn_per_e", camera.gain_dn_per_e);
    check::positive("full_well_e", camera.full_well_e);
    if (!(camera.full_well_e <= 1e12))
        throw InvalidArgument(concat("full_well_e = ", number_text(camera.full_well_e),
                                     " is outside the valid range (0, 1e12]"));
    check::non_negative("read_noise_e", camera.read_noise_e);
    if (camera.bit_depth != 8 && camera.bit_depth != 12 && camera.bit_depth != 14 &&
        camera.bit_depth != 16)
        throw InvalidArgument(concat("bit_depth = ", std::to_string(camera.bit_depth),
                                     " is not one of 8, 12, 14, 16"));
    check::non_negative("black_level_dn", camera.black_level_dn);
    if (!(camera.black_level_dn < camera.white_level_dn()))
        throw InvalidArgument(concat("black_level_dn = ", number_text(camera.black_level_dn),
                                     " is outside the valid range [0, ",
                                     number_text(camera.white_level_dn()), ") for ",
                                     std::to_string(camera.bit_depth), " bits"));
    if (!(camera.gamma >= 0.1 && camera.gamma <= 10.0))
        throw InvalidArgument(
            concat("gamma = ", number_text(camera.gamma), " is outside the valid range [0.1, 10]"));
    if (!(camera.vignetting >= 0.0 && camera.vignetting <= 1.0))
        throw InvalidArgument(concat("vignetting = ", number_text(camera.vignetting),
                                     " is outside the valid range [0, 1]"));
}

double surface_brightness(const SurfaceTruth& truth, const Geometry& geom) {
    switch (truth.model) {
        case BrightnessModel::VeryRough:
            return very_rough_brightness(geom, truth.sigma_over_T(), truth.correlation,
                                         truth.factor, truth.radiometry);
        case BrightnessModel::MeanScatteredPower: {
            ModelOptions options = truth.model_options;
            options.factor = truth.factor;
            options.radiometry = truth.radiometry;
            return mean_scattered_power(geom, {truth.sigma_um, truth.T_um, truth.correlation},
                                        options)
                .brightness;
        }
        case BrightnessModel::Lambert:
            return lambert_brightness(geom.theta_i_rad);
        case BrightnessModel::OrenNayar:
            return oren_nayar_radiance(geom, truth.oren_nayar);
        case BrightnessModel::Lafortune:
            return lafortune_diffuse_brightness(geom, truth.lafortune_n);
        case BrightnessModel::Tabulated: {
            if (!truth.tabulated)
                throw InvalidArgument("tabulated brightness: no table or callback given");
            const double value = truth.tabulated(geom);
            if (!std::isfinite(value) || value < 0.0)
                throw InvalidArgument(concat(
                    "tabulated brightness = ", number_text(value), " at theta_i = ",
                    number_text(rad_to_deg(geom.theta_i_rad)), " deg is not a finite value >= 0"));
            return value;
        }
    }
    return 0.0;
}

std::function<double(const Geometry&)> table_brightness(BrightnessTable table) {
    const std::array<std::pair<const std::vector<double>*, const char*>, 3> axes{{
        {&table.theta_i_rad, "theta_i"},
        {&table.theta_s_rad, "theta_s"},
        {&table.phi_s_rad, "phi_s"},
    }};
    for (const auto& [axis, name] : axes) {
        if (axis->size() < 2)
            throw InvalidArgument(concat("brightness table: the ", name, " axis has ",
                                         std::to_string(axis->size()),
                                         " points; at least 2 are needed"));
        for (std::size_t k = 0; k < axis->size(); ++k) {
            if (!std::isfinite((*axis)[k]) || (k > 0 && !((*axis)[k] > (*axis)[k - 1])))
                throw InvalidArgument(concat("brightness table: the ", name,
                                             " axis must be finite and strictly increasing"));
        }
    }
    const std::size_t expected =
        table.theta_i_rad.size() * table.theta_s_rad.size() * table.phi_s_rad.size();
    if (table.values.size() != expected)
        throw InvalidArgument(concat("brightness table: ", std::to_string(table.values.size()),
                                     " values for a grid of ", std::to_string(expected)));
    for (double v : table.values)
        if (!std::isfinite(v) || v < 0.0)
            throw InvalidArgument(
                concat("brightness table: value ", number_text(v), " is not a finite value >= 0"));
    return [t = std::move(table)](const Geometry& g) {
        // Index and weight along one axis, clamped at the edges.
        auto locate = [](const std::vector<double>& axis, double x) {
            if (x <= axis.front()) return std::pair<std::size_t, double>{0, 0.0};
            if (x >= axis.back()) return std::pair<std::size_t, double>{axis.size() - 2, 1.0};
            const auto it = std::upper_bound(axis.begin(), axis.end(), x);
            const auto k = static_cast<std::size_t>(it - axis.begin()) - 1;
            return std::pair<std::size_t, double>{k, (x - axis[k]) / (axis[k + 1] - axis[k])};
        };
        const auto [a, wa] = locate(t.theta_i_rad, g.theta_i_rad);
        const auto [b, wb] = locate(t.theta_s_rad, g.theta_s_rad);
        const double phi = std::abs(std::remainder(g.phi_s_rad, 2.0 * kPi));  // [0, π]
        const auto [c, wc] = locate(t.phi_s_rad, phi);
        const std::size_t ns = t.theta_s_rad.size();
        const std::size_t np = t.phi_s_rad.size();
        double sum = 0.0;
        for (int da = 0; da < 2; ++da)
            for (int db = 0; db < 2; ++db)
                for (int dc = 0; dc < 2; ++dc) {
                    const double w =
                        (da ? wa : 1.0 - wa) * (db ? wb : 1.0 - wb) * (dc ? wc : 1.0 - wc);
                    if (w == 0.0) continue;
                    sum += w * t.values[((a + da) * ns + (b + db)) * np + (c + dc)];
                }
        return sum;
    };
}

// ---------------------------------------------------------------------------------------------
// Rendering

namespace {

// The truths and labels checked against the image and each other.
void check_truths(const Scene& scene, const std::vector<SurfaceTruth>& truths,
                  const std::vector<std::int32_t>& labels) {
    if (truths.empty()) throw InvalidArgument("truths: at least one surface truth is needed");
    const std::size_t W = scene.width, H = scene.height, N = W * H;
    if (!labels.empty()) {
        if (labels.size() != N)
            throw InvalidArgument(concat("labels: ", std::to_string(labels.size()),
                                         " entries for a ", std::to_string(W), " x ",
                                         std::to_string(H), " image (need width * height)"));
        for (std::int32_t l : labels)
            if (l < 0 || static_cast<std::size_t>(l) >= truths.size())
                throw InvalidArgument(concat("labels: label ", std::to_string(l),
                                             " is outside the valid range [0, ",
                                             std::to_string(truths.size() - 1), "]"));
    }
    for (std::size_t k = 0; k < truths.size(); ++k) {
        const SurfaceTruth& t = truths[k];
        const std::string which = concat("truth ", std::to_string(k), " ");
        if (!(t.sigma_um > 0.0 && std::isfinite(t.sigma_um)))
            throw InvalidArgument(
                concat(which, "sigma_um = ", number_text(t.sigma_um), " must be finite and > 0"));
        if (!(t.T_um > 0.0 && std::isfinite(t.T_um)))
            throw InvalidArgument(
                concat(which, "T_um = ", number_text(t.T_um), " must be finite and > 0"));
        if (t.model == BrightnessModel::Tabulated && !t.tabulated)
            throw InvalidArgument(concat(which, "model tabulated needs a table or a callback"));
    }
}

// A capture of the scene's size with the layers the options keep, all zero.
Capture empty_capture(const Scene& scene, const CameraModel& camera,
                      const CaptureOptions& options) {
    const std::size_t N = scene.width * scene.height;
    Capture out;
    out.width = scene.width;
    out.height = scene.height;
    out.bit_depth = camera.bit_depth;
    if (options.keep_radiance) assign_large(out.radiance, N, 0.0F);
    if (options.keep_expected_dn) assign_large(out.expected_dn, N, 0.0F);
    assign_large(out.dn, N, std::uint16_t{0});
    assign_large(out.saturated, N, std::uint8_t{0});
    if (options.keep_geometry) {
        out.label.resize(N);
        out.theta_i_rad.resize(N);
        out.theta_s_rad.resize(N);
        out.phi_s_rad.resize(N);
        out.normal.resize(3 * N);
    }
    return out;
}

// One row's shot noise: the electrons collected for the mean mu_e, capped at the full well
// (docs/simulation-captures.md, "Camera"). A mean repeated from the previous pixel of the row
// draws from the inversion table (exact; the rule depends on the row alone, so threads do not
// matter), any other from Boost's Poisson distribution.
class ShotNoise {
  public:
    template <class Engine>
    double electrons(const CameraModel& camera, double mu_e, Engine& engine) {
        double n_e = mu_e;
        if (!(mu_e <= 1e300)) {
            n_e = camera.full_well_e;  // overflowed: saturated whatever the draw
        } else if (camera.shot_noise && mu_e > 0.0) {
            if (mu_e - camera.full_well_e > 40.0 * std::sqrt(mu_e)) {
                n_e = camera.full_well_e;  // a draw below the full well has probability < 1e-300
            } else {
                const bool repeated = mu_e == previous_mu_ && mu_e >= PoissonTable::kMinMean &&
                                      mu_e <= PoissonTable::kMaxMean;
                if (repeated) {
                    if (table_.mean() != mu_e) table_.build(mu_e);
                    n_e = static_cast<double>(table_(engine));
                } else {
                    if (shot_.mean() != mu_e)
                        shot_ = boost::random::poisson_distribution<std::int64_t, double>(mu_e);
                    n_e = static_cast<double>(shot_(engine));
                }
            }
        }
        previous_mu_ = mu_e;
        return n_e;
    }
    // A new row: no previous mean.
    void new_row() { previous_mu_ = -1.0; }

  private:
    boost::random::poisson_distribution<std::int64_t, double> shot_{1.0};
    PoissonTable table_;
    double previous_mu_ = -1.0;
};

// Everything the rows of one capture share.
struct RenderJob {
    const Scene& scene;
    const std::vector<SurfaceTruth>& truths;
    const std::vector<std::int32_t>& labels;
    const CameraModel& camera;
    const CaptureOptions& options;
    Capture& out;
    CameraAxes frame;
    double radius = 0.0;
    double half_w = 0.0, half_h = 0.0, half_diag2 = 0.0;
    double white = 0.0;
    double k_t = 0.0;  // electrons per unit radiance
};

// The pixel counts of a block of rows.
struct BlockCounts {
    std::size_t object = 0, saturated = 0;
};

// The last brightness computed: a plane, or neighbouring pixels of one region on a flat patch,
// repeat the same normal.
struct LastBrightness {
    Eigen::Vector3d normal{kNaN, kNaN, kNaN};
    std::int32_t label = -2;
    double brightness = 0.0;
    std::optional<Geometry> geometry;
};

// The camera's DN of `radiance` at pixel i (column col) of one row, with its saturation flag and
// the kept layers (docs/simulation-captures.md, "Camera").
template <class Engine>
bool expose_pixel(const RenderJob& job, std::size_t i, std::size_t col, double dy, double radiance,
                  ShotNoise& shot, Engine& engine,
                  boost::random::normal_distribution<double>& read_noise) {
    const CameraModel& camera = job.camera;
    const double dx = static_cast<double>(col) + 0.5 - job.half_w;
    const double vignette = camera.vignetting > 0.0
                                ? 1.0 - camera.vignetting * (dx * dx + dy * dy) / job.half_diag2
                                : 1.0;
    const double mu_e = job.k_t * radiance * vignette;
    double n_e = shot.electrons(camera, mu_e, engine);
    bool saturated = false;
    if (n_e >= camera.full_well_e) {
        n_e = camera.full_well_e;
        saturated = true;
    }
    const double x_e =
        camera.read_noise_e > 0.0 ? n_e + camera.read_noise_e * read_noise(engine) : n_e;
    const double signal = camera.gain_dn_per_e * x_e + camera.black_level_dn;
    if (signal >= job.white) saturated = true;
    const double clipped = std::clamp(signal, 0.0, job.white);
    const double encoded = camera.response == Response::Linear
                               ? clipped
                               : job.white * encode_response(camera, clipped / job.white);
    job.out.dn[i] = static_cast<std::uint16_t>(std::floor(encoded + 0.5));
    job.out.saturated[i] = saturated ? 1 : 0;
    if (job.options.keep_expected_dn)
        job.out.expected_dn[i] =
            static_cast<float>(camera.gain_dn_per_e * mu_e + camera.black_level_dn);
    return saturated;
}

// The geometry layers of pixel i (NaN off the object).
void keep_geometry(Capture& out, std::size_t i, std::int32_t label,
                   const std::optional<Geometry>& geometry,
                   const std::optional<Eigen::Vector3d>& normal) {
    out.label[i] = label;
    out.theta_i_rad[i] = geometry ? static_cast<float>(geometry->theta_i_rad) : kNaNf;
    out.theta_s_rad[i] = geometry ? static_cast<float>(geometry->theta_s_rad) : kNaNf;
    out.phi_s_rad[i] = geometry ? static_cast<float>(geometry->phi_s_rad) : kNaNf;
    for (int c = 0; c < 3; ++c)
        out.normal[3 * i + static_cast<std::size_t>(c)] =
            normal ? static_cast<float>((*normal)[c]) : kNaNf;
}

// Rows [row_begin, row_end) with their own caches and counts; each row draws from its own
// stream, so the split into blocks does not change the result.
void render_rows(const RenderJob& job, std::size_t row_begin, std::size_t row_end,
                 BlockCounts& counts) {
    const Scene& scene = job.scene;
    const std::size_t W = scene.width;
    const double s = scene.pixel_size_um;
    LastBrightness last;
    ShotNoise shot;
    for (std::size_t row = row_begin; row < row_end; ++row) {
        boost::random::mt19937_64 engine(splitmix64(job.camera.seed ^ splitmix64(row)));
        boost::random::normal_distribution<double> read_noise(0.0, 1.0);
        shot.new_row();
        const double y_img = (job.half_h - static_cast<double>(row) - 0.5) * s;
        const double dy = static_cast<double>(row) + 0.5 - job.half_h;
        for (std::size_t col = 0; col < W; ++col) {
            const std::size_t i = row * W + col;
            const double x_img = (static_cast<double>(col) + 0.5 - job.half_w) * s;
            const Eigen::Vector3d p = x_img * job.frame.right + y_img * job.frame.up;
            const auto normal = surface_normal(scene.shape, p, scene.view, job.radius);
            double radiance = scene.background_radiance;
            std::int32_t label = -1;
            std::optional<Geometry> geometry;
            if (normal) {
                ++counts.object;
                label = job.labels.empty() ? 0 : job.labels[i];
                if (label == last.label && *normal == last.normal) {
                    radiance = last.brightness;
                    geometry = last.geometry;
                } else {
                    geometry = geometry_from_vectors(*normal, scene.light, scene.view);
                    radiance = geometry
                                   ? surface_brightness(job.truths[static_cast<std::size_t>(label)],
                                                        *geometry)
                                   : 0.0;
                    last = {*normal, label, radiance, geometry};
                }
            }
            const bool saturated =
                expose_pixel(job, i, col, dy, radiance, shot, engine, read_noise);
            counts.saturated += saturated ? 1 : 0;
            if (job.options.keep_radiance) job.out.radiance[i] = static_cast<float>(radiance);
            if (job.options.keep_geometry) keep_geometry(job.out, i, label, geometry, normal);
        }
    }
}

}  // namespace

Capture render_capture(const Scene& scene, const std::vector<SurfaceTruth>& truths,
                       const std::vector<std::int32_t>& labels, const CameraModel& camera,
                       const CaptureOptions& options) {
    check_scene(scene);
    check_camera(camera);
    check_truths(scene, truths, labels);
    const std::size_t W = scene.width, H = scene.height, N = W * H;
    Capture out = empty_capture(scene, camera, options);

    const double half_w = 0.5 * static_cast<double>(W), half_h = 0.5 * static_cast<double>(H);
    const RenderJob job{scene,
                        truths,
                        labels,
                        camera,
                        options,
                        out,
                        camera_axes(scene.view),
                        scene_radius_um(scene),
                        half_w,
                        half_h,
                        half_w * half_w + half_h * half_h,
                        camera.white_level_dn(),
                        camera.electrons_per_unit_s * camera.exposure_s};

    std::size_t threads =
        options.threads != 0 ? options.threads : std::max(1U, std::thread::hardware_concurrency());
    threads = std::min({threads, H, std::size_t{64}});
    if (N < 65536) threads = 1;  // not worth a thread
    std::vector<BlockCounts> counts(threads);
    if (threads == 1) {
        render_rows(job, 0, H, counts[0]);
    } else {
        std::vector<std::exception_ptr> errors(threads);
        std::vector<std::thread> workers;
        for (std::size_t t = 0; t < threads; ++t) {
            workers.emplace_back([&, t] {
                try {
                    render_rows(job, H * t / threads, H * (t + 1) / threads, counts[t]);
                } catch (...) {
                    errors[t] = std::current_exception();
                }
            });
        }
        for (auto& w : workers) w.join();
        for (const auto& e : errors)
            if (e) std::rethrow_exception(e);
    }
    for (const BlockCounts& c : counts) {
        out.object_count += c.object;
        out.saturated_count += c.saturated;
    }
    return out;
}

}  // namespace roughscope::simulation
