// A lamp and a camera at a finite distance (finite_distance.hpp, finite_distance_detail.hpp).
#include "roughscope/measure/finite_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "finite_distance_detail.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {

Eigen::Vector3d plane_point_mm(const SamplePlane& plane, std::size_t width, std::size_t height,
                               double column, double row) {
    for (const double s : plane.pixel_size_mm)
        if (!(s >= kMinPixelSizeMm && s <= kMaxPixelSizeMm))
            throw InvalidArgument(concat("sample_plane.pixel_size_mm = ", check::format_number(s),
                                         " must be in [", check::format_number(kMinPixelSizeMm),
                                         ", ", check::format_number(kMaxPixelSizeMm), "] mm"));
    const std::array<double, 2> origin = plane.origin_px.value_or(
        std::array<double, 2>{static_cast<double>(width) / 2, static_cast<double>(height) / 2});
    for (const double o : origin)
        if (!std::isfinite(o))
            throw InvalidArgument(
                concat("sample_plane.origin_px = ", check::format_number(o), " must be finite"));
    return {(column + 0.5 - origin[0]) * plane.pixel_size_mm[0],
            -(row + 0.5 - origin[1]) * plane.pixel_size_mm[1], 0.0};
}

namespace detail {
namespace {

// DataError naming the capture file's key, or InvalidArgument for a request built in code.
[[noreturn]] void refuse(const MeasureRequest& request, const std::string& key,
                         const std::string& reason) {
    if (request.source.empty()) throw InvalidArgument(concat("measure: ", key, ": ", reason));
    throw DataError(concat(request.source, ": ", key, ": ", reason));
}

// The unit vector from X toward the point P.
Eigen::Vector3d toward(const Eigen::Vector3d& P, const Eigen::Vector3d& X) {
    return (P - X).normalized();
}

// The geometry (§2) at plane point X of capture `spec`: its light from the lamp position (or
// the direction), its view toward the camera position (or the direction); nullopt below the
// horizon.
std::optional<Geometry> geometry_at(const CaptureSpec& spec, const Eigen::Vector3d& X) {
    const Eigen::Vector3d L =
        spec.light_position_mm ? toward(*spec.light_position_mm, X) : *spec.light;
    const Eigen::Vector3d V =
        spec.view_position_mm ? toward(*spec.view_position_mm, X) : *spec.view;
    return geometry_from_vectors(Eigen::Vector3d::UnitZ(), L, V);
}

// The region's centroid (pixel coordinates of the centres) and a uniform subsample of its
// pixels in scan order: every stride-th pixel, each the middle of its block of `stride`.
struct RegionPoints {
    double column = 0.0, row = 0.0;                  // centroid, pixel coordinates
    std::vector<std::pair<double, double>> samples;  // (column, row)
};

RegionPoints region_points(const RegionSpans& spans) {
    RegionPoints out;
    const std::size_t n = spans.pixel_count;
    if (n == 0) return out;
    double sum_column = 0.0, sum_row = 0.0;
    const std::size_t stride = (n + kFiniteDistanceSamplePoints - 1) / kFiniteDistanceSamplePoints;
    std::size_t next = stride / 2, start = 0;  // the next sampled index; the span's first index
    for (const PixelSpan& s : spans.spans) {
        const std::size_t count = s.x_end - s.x_begin;
        sum_column += static_cast<double>(count) * (static_cast<double>(s.x_begin + s.x_end) / 2);
        sum_row += static_cast<double>(count) * static_cast<double>(s.row);
        for (; next < start + count; next += stride)
            out.samples.emplace_back(static_cast<double>(s.x_begin + (next - start)),
                                     static_cast<double>(s.row));
        start += count;
    }
    // Σ over the pixels of (x + ½) is count · (x_begin + x_end)/2; the row's centre is row + ½
    // (plane_point_mm adds the ½ to both).
    out.column = sum_column / static_cast<double>(n) - 0.5;
    out.row = sum_row / static_cast<double>(n);
    return out;
}

// The model B(geom(X))/B(geom(X0)) at the unknown x.
double model_ratio(const CorrectionModel& m, const Geometry& at, const Geometry& centroid,
                   double x) {
    if (m.quantity == CorrectedQuantity::CorrelationLength)
        return model_ratio_diffuse(at, centroid, m.sigma_um, x, m.correlation, m.options);
    return model_ratio_very_rough(at, centroid, x, m.correlation, m.options);
}

std::optional<double>& recorded(FiniteDistance& fd, CorrectedQuantity q) {
    switch (q) {
        case CorrectedQuantity::SlopeGaussian:
            return fd.correction_gaussian;
        case CorrectedQuantity::SlopeExponential:
            return fd.correction_exponential;
        case CorrectedQuantity::CorrelationLength:
            break;
    }
    return fd.correction_T;
}

// r0² of a capture: the lamp's squared distance at the centroid (1 for a collimated light).
double lamp_distance_squared(const CaptureMeasurement& c) {
    if (!c.finite_distance || !c.finite_distance->lamp_distance_mm) return 1.0;
    const double r0 = *c.finite_distance->lamp_distance_mm;
    return r0 * r0;
}

}  // namespace

bool has_position(const CaptureSpec& spec) {
    return spec.light_position_mm.has_value() || spec.view_position_mm.has_value();
}

bool has_position(const MeasureRequest& request) {
    return std::any_of(request.captures.begin(), request.captures.end(),
                       [](const CaptureSpec& s) { return has_position(s); });
}

void check_finite_distance(const MeasureRequest& request) {
    if (request.sample_plane) {
        // The pixel size and origin: plane_point_mm's checks.
        try {
            (void)plane_point_mm(*request.sample_plane, 1, 1, 0.0, 0.0);
        } catch (const InvalidArgument& e) {
            if (request.source.empty()) throw;
            throw DataError(concat(request.source, ": ", e.what()));
        }
    }
    std::optional<bool> lamp_positions;  // of the diffuse captures: all or none
    for (std::size_t k = 0; k < request.captures.size(); ++k) {
        const CaptureSpec& spec = request.captures[k];
        const std::string name = concat("captures[", std::to_string(k), "]");
        const std::array<std::pair<const char*, const std::optional<Eigen::Vector3d>*>, 2> points{
            {{"light", &spec.light_position_mm}, {"view", &spec.view_position_mm}}};
        for (const auto& [key, point] : points) {
            if (!*point) continue;
            const std::string at = concat(name, ".", key, ".position_mm");
            const Eigen::Vector3d& p = **point;
            if (!p.allFinite()) refuse(request, at, "must be three finite numbers (mm)");
            if (!(p.z() > 0.0))
                refuse(request, at,
                       concat("z = ", check::format_number(p.z()),
                              " mm must be > 0 (above the sample's plane z = 0, normal +z)"));
            if (!request.sample_plane)
                refuse(request, at,
                       "a position needs the capture file's \"sample_plane\" (pixel_size_mm, "
                       "origin_px): how the image's pixels map to the sample's plane");
            if (!request.roi)
                refuse(request, at, "a position needs the region (\"roi\") it is measured on");
            if (request.object.shape != ObjectShape::Plane)
                refuse(request, at, "positions are for a flat sample (object.shape plane)");
            if (spec.role != CaptureRole::Diffuse)
                refuse(request, at,
                       "positions are for diffuse captures; a specular capture is taken in the "
                       "mirror direction of one light direction");
        }
        if (!spec.light_position_mm && !spec.light)
            if (spec.view_position_mm)
                refuse(request, concat(name, ".light"),
                       "a capture with a view position needs its light (a direction or a "
                       "position)");
        if (spec.role != CaptureRole::Diffuse) continue;
        const bool lamp = spec.light_position_mm.has_value();
        if (lamp_positions && *lamp_positions != lamp)
            refuse(request, concat(name, ".light"),
                   "either every diffuse capture's light is a position (one point lamp, the same "
                   "intensity in every capture) or none: a point lamp's 1/r² cannot be compared "
                   "with a collimated light's unknown irradiance");
        lamp_positions = lamp;
    }
}

void locate_captures(const MeasureRequest& request, const RegionSpans& spans,
                     std::vector<CaptureMeasurement>& captures) {
    if (!has_position(request) || !request.sample_plane) return;
    const RegionPoints points = region_points(spans);
    if (points.samples.empty()) return;
    const SamplePlane& plane = *request.sample_plane;
    const Eigen::Vector3d X0 =
        plane_point_mm(plane, spans.width, spans.height, points.column, points.row);
    for (std::size_t k = 0; k < captures.size(); ++k) {
        CaptureSpec& spec = captures[k].spec;
        if (!has_position(spec)) continue;
        const std::string key = concat("captures[", std::to_string(k), "]");
        FiniteDistance fd;
        fd.centroid_mm = X0;
        if (spec.light_position_mm) {
            fd.lamp_distance_mm = (*spec.light_position_mm - X0).norm();
            spec.light = toward(*spec.light_position_mm, X0);
        }
        if (spec.view_position_mm) {
            fd.camera_distance_mm = (*spec.view_position_mm - X0).norm();
            spec.view = toward(*spec.view_position_mm, X0);
        }
        if (!spec.view) spec.view = Eigen::Vector3d::UnitZ();
        const auto g0 = geometry_at(spec, X0);
        if (!g0) refuse(request, key, "the light or the view is at or below the sample's plane");
        spec.geometry = *g0;
        fd.theta_i_min_deg = fd.theta_s_min_deg = std::numeric_limits<double>::infinity();
        fd.theta_i_max_deg = fd.theta_s_max_deg = -std::numeric_limits<double>::infinity();
        for (const auto& [column, row] : points.samples) {
            const Eigen::Vector3d X = plane_point_mm(plane, spans.width, spans.height, column, row);
            const auto g = geometry_at(spec, X);
            if (!g)
                refuse(request, key,
                       "the light or the view is at or below the sample's plane at a pixel of "
                       "the region");
            fd.point_geometry.push_back(*g);
            const double r0_over_r =
                spec.light_position_mm ? *fd.lamp_distance_mm / (*spec.light_position_mm - X).norm()
                                       : 1.0;
            fd.point_weight.push_back(r0_over_r * r0_over_r);
            fd.theta_i_min_deg = std::min(fd.theta_i_min_deg, rad_to_deg(g->theta_i_rad));
            fd.theta_i_max_deg = std::max(fd.theta_i_max_deg, rad_to_deg(g->theta_i_rad));
            fd.theta_s_min_deg = std::min(fd.theta_s_min_deg, rad_to_deg(g->theta_s_rad));
            fd.theta_s_max_deg = std::max(fd.theta_s_max_deg, rad_to_deg(g->theta_s_rad));
        }
        captures[k].finite_distance = std::move(fd);
    }
}

double correction_factor(const CaptureMeasurement& c, const CorrectionModel& model, double x) {
    if (!c.finite_distance) return 1.0;
    const FiniteDistance& fd = *c.finite_distance;
    double sum = 0.0;
    for (std::size_t j = 0; j < fd.point_geometry.size(); ++j)
        sum += fd.point_weight[j] * model_ratio(model, fd.point_geometry[j], c.spec.geometry, x);
    return sum / static_cast<double>(fd.point_geometry.size());
}

double corrected_ratio(double ratio, const CorrectionModel& model,
                       const std::function<double(double)>& solve, CaptureMeasurement& c1,
                       CaptureMeasurement& c2) {
    if (!c1.finite_distance && !c2.finite_distance) return ratio;
    // (r10/r20)²: the lamp's inverse square between the captures at the centroid.
    const double inverse_square = lamp_distance_squared(c1) / lamp_distance_squared(c2);
    auto corrected = [&](double x) {
        return ratio * inverse_square * correction_factor(c2, model, x) /
               correction_factor(c1, model, x);
    };
    constexpr int kMaxSteps = 50;
    constexpr double kRelativeTolerance = 1e-10;
    double x = solve(ratio);
    for (int step = 0; step < kMaxSteps; ++step) {
        const double next = solve(corrected(x));
        const bool converged = std::abs(next - x) <= kRelativeTolerance * std::abs(next);
        x = next;
        if (converged) {
            recorded(*c1.finite_distance, model.quantity) = correction_factor(c1, model, x);
            if (c2.finite_distance)
                recorded(*c2.finite_distance, model.quantity) = correction_factor(c2, model, x);
            return corrected(x);
        }
    }
    throw NoSolution(concat("the finite-distance correction did not converge in ",
                            std::to_string(kMaxSteps), " steps (last estimate ",
                            check::format_number(x), ")"));
}

double ratio_correction(const CaptureMeasurement& c1, const CaptureMeasurement& c2,
                        CorrectedQuantity quantity) {
    if (!c1.finite_distance && !c2.finite_distance) return 1.0;
    auto factor = [&](const CaptureMeasurement& c) {
        if (!c.finite_distance) return 1.0;
        FiniteDistance fd = *c.finite_distance;  // (recorded() takes a mutable one)
        return recorded(fd, quantity).value_or(1.0);
    };
    return lamp_distance_squared(c1) / lamp_distance_squared(c2) * factor(c2) / factor(c1);
}

CorrelationComparison fit_corrected(const std::vector<CaptureMeasurement*>& diffuse,
                                    const FitOptions& options,
                                    const std::array<std::optional<double>, 2>& pair_slopes) {
    CorrelationComparison out;
    std::array<FitResult, 2> fits;
    for (std::size_t i = 0; i < 2; ++i) {
        const Correlation correlation = i == 0 ? Correlation::Gaussian : Correlation::Exponential;
        CorrectionModel model;
        model.quantity =
            i == 0 ? CorrectedQuantity::SlopeGaussian : CorrectedQuantity::SlopeExponential;
        model.correlation = correlation;
        model.options.factor = options.factor;
        model.options.radiometry = options.radiometry;
        std::vector<Measurement> measurements;
        for (CaptureMeasurement* c : diffuse) {
            Measurement m;
            m.geometry = c->spec.geometry;
            const double f = pair_slopes[i] ? correction_factor(*c, model, *pair_slopes[i]) : 1.0;
            if (pair_slopes[i] && c->finite_distance)
                recorded(*c->finite_distance, model.quantity) = f;
            m.brightness = c->brightness * lamp_distance_squared(*c) / f;
            const double e = c->brightness_relative_stderr;
            m.weight = e > 0.0 ? 1.0 / (e * e) : 1.0;
            measurements.push_back(m);
        }
        // compare_correlations ranks both fits; each correlation's own factors give its fit.
        CorrelationComparison one = compare_correlations(measurements, options);
        if (i == 0)
            out = std::move(one);
        else
            out.exponential = std::move(one.exponential);
    }
    // The ranking of compare_correlations (fit.hpp) on the two fits kept.
    const bool g_ok = out.gaussian.status != SolverStatus::NotIdentifiable;
    const bool e_ok = out.exponential.status != SolverStatus::NotIdentifiable;
    out.preferred = (g_ok && !e_ok) || ((g_ok == e_ok) && out.gaussian.aic <= out.exponential.aic)
                        ? Correlation::Gaussian
                        : Correlation::Exponential;
    out.delta_aic = g_ok && e_ok ? std::abs(out.gaussian.aic - out.exponential.aic)
                                 : std::numeric_limits<double>::quiet_NaN();
    return out;
}

}  // namespace detail
}  // namespace roughscope::image
