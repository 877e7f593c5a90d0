// The capture file of `roughscope measure` (measure.hpp, docs/measure.md): JSON to a
// MeasureRequest. Every key is checked: an unknown key, a wrong type or a value out of range is a
// DataError naming the file and the key.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "io/json_reader.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

using io::JsonNode;

// A light or view direction closer to the sample's plane than this cosine is grazing: no
// brightness to measure (scattering/geometry.hpp's horizon).
constexpr double kGrazingCos = 1e-12;

// What the capture file adds to the typed reader: paths relative to the file's folder, and the
// library's ranges of exposures and lengths.
struct Context {
    std::filesystem::path dir;

    // An exposure time (s): kMinExposureS … kMaxExposureS (measure.hpp).
    static double exposure(const JsonNode& j) {
        return j.number(kMinExposureS, kMaxExposureS, " s");
    }
    // A length (µm) the scattering functions take: kMinLengthUm … kMaxLengthUm.
    static double length(const JsonNode& j) { return j.number(kMinLengthUm, kMaxLengthUm, " µm"); }
    std::string path(const JsonNode& j) const {
        const std::string p = j.string();
        if (p.empty()) j.fail("must name a file");
        const std::filesystem::path fp(p);
        return (fp.is_absolute() ? fp : dir / fp).lexically_normal().string();
    }
};

// A direction: any non-zero vector, normalised (scaled by its largest component first, so that
// neither a huge nor a tiny one overflows or underflows).
Eigen::Vector3d unit_vector(const JsonNode& j) {
    const auto v = j.numbers(3);
    Eigen::Vector3d d(v[0], v[1], v[2]);
    const double largest = d.cwiseAbs().maxCoeff();
    if (!(largest > 0.0)) j.fail("must be a non-zero vector");
    d /= largest;
    return d / d.norm();
}

// [{"image": FILE, "exposure_s": t}, ...]: an exposure bracket (≥ 2 photographs).
std::vector<BracketShot> parse_bracket(const Context& ctx, const JsonNode& j) {
    if (!j.is_array() || j.size() < 2)
        j.fail(
            concat("must be an array of at least 2 {\"image\": FILE, \"exposure_s\": "
                   "t} photographs, not ",
                   j.json().dump()));
    std::vector<BracketShot> shots;
    for (const JsonNode& shot : j.array(2)) {
        shot.only({"image", "exposure_s"});
        if (!shot.has("image") || !shot.has("exposure_s"))
            shot.fail("needs \"image\" and \"exposure_s\"");
        shots.push_back(
            BracketShot{ctx.path(shot.at("image")), Context::exposure(shot.at("exposure_s"))});
    }
    return shots;
}

// {"rect": ...} | {"circle": ...} | {"polygon": ...} | {"mask": FILE}; `allowed` lists the keys
// the object may hold (a map region also has its "name").
Region parse_region(const Context& ctx, const JsonNode& j,
                    std::initializer_list<std::string_view> allowed = {"rect", "circle", "polygon",
                                                                       "mask"}) {
    j.only(allowed);
    const int shapes = static_cast<int>(j.has("rect")) + static_cast<int>(j.has("circle")) +
                       static_cast<int>(j.has("polygon")) + static_cast<int>(j.has("mask"));
    if (shapes != 1) j.fail("must have exactly one of rect, circle, polygon, mask");
    if (j.has("rect")) {
        const auto r = j.at("rect").numbers(4);
        return RectangleRegion{r[0], r[1], r[2], r[3]};
    }
    if (j.has("circle")) {
        const auto c = j.at("circle").numbers(3);
        return CircleRegion{c[0], c[1], c[2]};
    }
    if (j.has("polygon")) {
        const JsonNode p = j.at("polygon");
        if (!p.is_array()) p.fail("must be an array of [x, y] points");
        std::vector<std::array<double, 2>> points;
        for (const JsonNode& point : p.array()) {
            const auto xy = point.numbers(2);
            points.push_back({xy[0], xy[1]});
        }
        return PolygonRegion{points};
    }
    const JsonNode mask = j.at("mask");
    const std::string file = ctx.path(mask);
    try {
        return mask_region_from_image(read_image(file));
    } catch (const Error& e) {  // missing, unreadable, not an image
        mask.fail(e.what());
    }
}

// A whole number in [lo, hi].
std::size_t whole(const JsonNode& j, long long lo, long long hi) {
    return static_cast<std::size_t>(j.integer(lo, hi));
}

EdgePoint point_px(const JsonNode& j) {
    const auto xy = j.numbers(2);
    EdgePoint p;
    p.x_px = xy[0];
    p.y_px = xy[1];
    return p;
}

void parse_sphere_object(const JsonNode& j, SphereOptions& o) {
    j.only({"shape", "circle", "threshold", "limb_fraction", "max_angle_deg", "cell_px",
            "max_cells", "min_cell_fraction"});
    if (j.has("circle")) {
        const JsonNode node = j.at("circle");
        const auto c = node.numbers(3);
        CircleFit circle;
        circle.centre_x_px = c[0];
        circle.centre_y_px = c[1];
        circle.radius_px = c[2];
        if (!(circle.radius_px > 0.0)) node.fail("the radius must be > 0");
        o.circle = circle;
    }
    if (j.has("threshold")) o.silhouette.threshold = j.at("threshold").positive();
    if (j.has("limb_fraction")) o.limb_fraction = j.at("limb_fraction").number();
    if (j.has("max_angle_deg")) o.max_angle_deg = j.at("max_angle_deg").number();
    if (j.has("cell_px")) o.cell_px = whole(j.at("cell_px"), 0, 65535);
    if (j.has("max_cells")) o.max_cells = whole(j.at("max_cells"), 1, 10000000);
    if (j.has("min_cell_fraction")) o.min_cell_fraction = j.at("min_cell_fraction").number();
    j.checked([&] { check_sphere_options(o); });
}

void parse_cylinder_object(const JsonNode& j, CylinderOptions& o) {
    j.only({"shape", "axis", "edges", "half", "bin_width_deg", "min_pixels_per_bin",
            "limb_fraction", "sigma_over_T", "fit_max_theta_i_deg", "departure_k", "departure_bins",
            "threshold"});
    if (j.has("axis") && j.has("edges")) j.fail("give the cylinder's axis or its edges, not both");
    if (j.has("axis")) {
        const JsonNode a = j.at("axis");
        a.only({"point_px", "direction", "radius_px"});
        if (!a.has("point_px") || !a.has("direction") || !a.has("radius_px"))
            a.fail("needs point_px [x, y], direction [dx, dy] and radius_px");
        const auto p = a.at("point_px").numbers(2);
        const auto d = a.at("direction").numbers(2);
        const double r = a.at("radius_px").positive();
        a.checked([&] { o.axis = cylinder_axis_from_line(p[0], p[1], d[0], d[1], r); });
    }
    if (j.has("edges")) {
        const JsonNode e = j.at("edges");
        const io::JsonValue& v = e.json();
        if (!v.is_array() || v.size() != 2 || !v[0].is_array() || v[0].size() != 2 ||
            !v[1].is_array() || v[1].size() != 2)
            e.fail("must be two edges of two points each: [[[x, y], [x, y]], [[x, y], [x, y]]]");
        const EdgePoint a0 = point_px(e.item(0).item(0));
        const EdgePoint a1 = point_px(e.item(0).item(1));
        const EdgePoint b0 = point_px(e.item(1).item(0));
        const EdgePoint b1 = point_px(e.item(1).item(1));
        e.checked([&] { o.axis = cylinder_axis_from_edges(a0, a1, b0, b1); });
    }
    if (j.has("half")) o.half = j.at("half").named(parse_cylinder_half);
    if (j.has("bin_width_deg")) o.bin_width_deg = j.at("bin_width_deg").number();
    if (j.has("min_pixels_per_bin"))
        o.min_pixels_per_bin = whole(j.at("min_pixels_per_bin"), 1, 1000000000);
    if (j.has("limb_fraction")) o.limb_fraction = j.at("limb_fraction").number();
    if (j.given("sigma_over_T")) o.sigma_over_T = j.at("sigma_over_T").positive();
    if (j.has("fit_max_theta_i_deg")) o.fit_max_theta_i_deg = j.at("fit_max_theta_i_deg").number();
    if (j.has("departure_k")) o.departure_k = j.at("departure_k").number();
    if (j.has("departure_bins")) o.departure_bins = whole(j.at("departure_bins"), 1, 1000000);
    if (j.has("threshold")) o.silhouette.threshold = j.at("threshold").positive();
    j.checked([&] { check_cylinder_options(o); });
}

// "object": {"shape": ..., shape options} (docs/measure.md "Curved objects and maps").
ObjectSpec parse_object(const Context& ctx, const JsonNode& j) {
    if (!j.is_object() || !j.has("shape"))
        j.fail(
            concat("must be an object with a \"shape\" (plane, cylinder, sphere, "
                   "normal_map, photometric_stereo), not ",
                   j.json().dump()));
    ObjectSpec spec;
    spec.shape = j.at("shape").named(parse_object_shape);
    switch (spec.shape) {
        case ObjectShape::Plane:
            j.only({"shape"});
            break;
        case ObjectShape::NormalMap:
            j.only({"shape", "file"});
            if (!j.has("file")) j.fail_at("file", "missing: the normal-map image");
            spec.normal_map = ctx.path(j.at("file"));
            break;
        case ObjectShape::Cylinder:
            parse_cylinder_object(j, spec.cylinder);
            break;
        case ObjectShape::Sphere:
            parse_sphere_object(j, spec.sphere);
            break;
        case ObjectShape::PhotometricStereo:
            j.only({"shape", "model", "shadow_fraction", "highlight_fraction"});
            if (j.has("model"))
                spec.photometric_stereo.model = j.at("model").named(parse_photometric_model);
            if (j.has("shadow_fraction"))
                spec.photometric_stereo.shadow_fraction = j.at("shadow_fraction").number(0.0, 0.99);
            if (j.has("highlight_fraction"))
                spec.photometric_stereo.highlight_fraction = j.at("highlight_fraction").positive();
            break;
    }
    return spec;
}

// "maps": {...} (docs/measure.md "Curved objects and maps", docs/maps.md).
MapRequest parse_maps(const Context& ctx, const JsonNode& j) {
    j.only({"window_px", "min_used_fraction", "max_shift_px", "allow_misregistration",
            "slightly_rough_max_sigma_over_T", "very_rough_min_sigma_over_T", "both_correlations",
            "ratio_layer", "regions"});
    MapRequest maps;
    MapOptions& o = maps.options;
    if (j.has("window_px")) o.window_px = whole(j.at("window_px"), 1, 4096);
    if (j.has("min_used_fraction")) {
        const JsonNode f = j.at("min_used_fraction");
        o.min_used_fraction = f.number();
        if (!(o.min_used_fraction > 0.0 && o.min_used_fraction <= 1.0))
            f.fail(concat(check::format_number(o.min_used_fraction), " must be in (0, 1]"));
    }
    if (j.has("max_shift_px")) {
        const JsonNode m = j.at("max_shift_px");
        o.max_shift_px = m.number();
        if (o.max_shift_px < 0.0) m.fail("must be ≥ 0");
    }
    if (j.has("allow_misregistration"))
        o.allow_misregistration = j.at("allow_misregistration").boolean();
    if (j.has("both_correlations")) o.both_correlations = j.at("both_correlations").boolean();
    if (j.has("ratio_layer")) o.ratio_layer = j.at("ratio_layer").boolean();
    if (j.has("slightly_rough_max_sigma_over_T"))
        o.slightly_rough_max_sigma_over_T = j.at("slightly_rough_max_sigma_over_T").positive();
    if (j.has("very_rough_min_sigma_over_T"))
        o.very_rough_min_sigma_over_T = j.at("very_rough_min_sigma_over_T").positive();
    if (!(o.very_rough_min_sigma_over_T >= o.slightly_rough_max_sigma_over_T))
        j.fail_at(j.has("very_rough_min_sigma_over_T") ? "very_rough_min_sigma_over_T"
                                                       : "slightly_rough_max_sigma_over_T",
                  concat("very_rough_min_sigma_over_T = ",
                         check::format_number(o.very_rough_min_sigma_over_T),
                         " must be at least slightly_rough_max_sigma_over_T = ",
                         check::format_number(o.slightly_rough_max_sigma_over_T)));
    if (j.has("regions")) {
        const JsonNode r = j.at("regions");
        if (!r.is_array()) r.fail("must be an array of {\"name\": ..., \"rect\": ...} regions");
        for (const JsonNode& region : r.array()) {
            if (!region.is_object() || !region.has("name"))
                region.fail("needs a \"name\" and one of rect, circle, polygon, mask");
            const std::string name = region.at("name").string();
            maps.regions.emplace_back(
                name, parse_region(ctx, region, {"name", "rect", "circle", "polygon", "mask"}));
        }
    }
    return maps;
}

// "sample_plane": {"pixel_size_mm": s | [sx, sy], "origin_px": [u0, v0]} (finite_distance.hpp).
SamplePlane parse_sample_plane(const JsonNode& j) {
    j.only({"pixel_size_mm", "origin_px"});
    if (!j.has("pixel_size_mm")) j.fail_at("pixel_size_mm", "missing: the side of a pixel (mm)");
    const JsonNode s = j.at("pixel_size_mm");
    SamplePlane plane;
    const std::vector<double> sizes = s.is_array() ? s.numbers(2) : std::vector{s.number()};
    for (std::size_t k = 0; k < 2; ++k) {
        const double v = sizes[std::min(k, sizes.size() - 1)];
        if (!(v >= kMinPixelSizeMm && v <= kMaxPixelSizeMm))
            s.fail(concat(check::format_number(v), " must be in [",
                          check::format_number(kMinPixelSizeMm), ", ",
                          check::format_number(kMaxPixelSizeMm), "] mm"));
        plane.pixel_size_mm[k] = v;
    }
    if (j.has("origin_px")) {
        const auto o = j.at("origin_px").numbers(2);
        plane.origin_px = std::array<double, 2>{o[0], o[1]};
    }
    return plane;
}

// The capture's geometry: theta_i_deg, theta_s_deg, phi_s_deg (paper frame) or light and view
// vectors (the sample's normal +z; for a curved object the camera frame, view +z by default, and
// neither given: L = V = +z, the retro-reflection of §5.2). Returns (θi, θs, φs) in degrees as
// typed (from vectors: as computed), for messages that echo them.
// "light": {"mirror_sphere": {"image": F, "circle": [cx, cy, r], "circle_uncertainty_px": u}}: the
// light's direction from
// the highlight of a mirror sphere in its own photograph (objects/mirror_sphere.hpp; camera frame,
// which is the sample's when the camera looks along its normal), read as the captures are; its
// standard uncertainty becomes the capture's theta_i_deg uncertainty (budget.hpp) unless the
// capture declares one.
Eigen::Vector3d calibrated_light(const Context& ctx, const JsonNode& j, const ReadOptions& read,
                                 CaptureSpec& spec) {
    j.only({"mirror_sphere"});
    const JsonNode m = j.at("mirror_sphere");
    m.only({"image", "circle", "circle_uncertainty_px"});
    MirrorSphereOptions options;
    if (m.has("circle_uncertainty_px"))
        options.circle_uncertainty_px = m.at("circle_uncertainty_px").number(0.0, 1e6, " px");
    const std::string image = ctx.path(m.at("image"));
    const std::vector<double> c = m.at("circle").numbers(3);
    CircleFit circle;
    circle.centre_x_px = c[0];
    circle.centre_y_px = c[1];
    circle.radius_px = c[2];
    MirrorSphereLight light;
    try {
        light = mirror_sphere_light(read_image(image, read), circle, nullptr, options);
    } catch (const Error& e) {
        m.fail(e.what());
    }
    spec.uncertainty.theta_i_deg = light.angle_uncertainty_deg;
    return light.light;
}

// {"position_mm": [x, y, z]}: a lamp or a camera at a finite distance (finite_distance.hpp), in
// mm in the sample frame, above the plane (z > 0). Returns its direction from the plane's origin
// (X = 0): measure() replaces it with the direction at the region's centroid.
bool is_position(const JsonNode& j) { return j.is_object() && j.has("position_mm"); }

Eigen::Vector3d position(const JsonNode& j, std::optional<Eigen::Vector3d>& point_mm) {
    if (j.has("mirror_sphere"))
        j.fail("give either \"mirror_sphere\" (a direction) or \"position_mm\", not both");
    j.only({"position_mm"});
    const JsonNode p = j.at("position_mm");
    const auto v = p.numbers(3);
    if (!(v[2] > 0.0))
        p.fail(concat("z = ", check::format_number(v[2]),
                      " mm must be > 0 (above the sample's plane z = 0, normal +z)"));
    point_mm = Eigen::Vector3d(v[0], v[1], v[2]);
    return point_mm->normalized();
}

std::array<double, 3> parse_capture_geometry(const Context& ctx, const JsonNode& c, bool curved,
                                             const ReadOptions& read, CaptureSpec& spec) {
    // A light vector, or one calibrated from a mirror sphere.
    const auto light_of = [&](const JsonNode& j) {
        return j.is_object() ? calibrated_light(ctx, j, read, spec) : unit_vector(j);
    };
    const bool angles = c.has("theta_i_deg") || c.has("theta_s_deg") || c.has("phi_s_deg");
    const bool vectors = c.has("light") || c.has("view");
    if (angles && vectors)
        c.fail("give either theta_i_deg, theta_s_deg, phi_s_deg or light and view, not both");
    auto degrees = [](const Geometry& g) {
        return std::array<double, 3>{rad_to_deg(g.theta_i_rad), rad_to_deg(g.theta_s_rad),
                                     rad_to_deg(g.phi_s_rad)};
    };
    for (const char* key : {"light", "view"})
        if (curved && c.has(key) && is_position(c.at(key)))
            c.fail_at(key, "a position (position_mm) is for a flat sample (object.shape plane)");
    if (curved && !angles) {
        spec.light = c.has("light") ? light_of(c.at("light")) : Eigen::Vector3d::UnitZ();
        spec.view = c.has("view") ? unit_vector(c.at("view")) : Eigen::Vector3d::UnitZ();
        for (const auto& [name, v] :
             {std::pair{"light", *spec.light}, std::pair{"view", *spec.view}})
            if (!(v.z() > kGrazingCos))
                c.fail_at(name,
                          "must point toward the camera side (z > 0; camera frame: x image right, "
                          "y image up, z toward the camera)");
        if (const auto g = geometry_from_vectors(Eigen::Vector3d::UnitZ(), *spec.light, *spec.view))
            spec.geometry = *g;
        return degrees(spec.geometry);
    }
    if (vectors) {
        const bool light_point = c.has("light") && is_position(c.at("light"));
        const bool sphere = c.has("light") && c.at("light").is_object() && !light_point;
        if (!c.has("light") || (!c.has("view") && !sphere))
            c.fail("light and view must both be given");
        const Eigen::Vector3d L =
            light_point ? position(c.at("light"), spec.light_position_mm) : light_of(c.at("light"));
        const Eigen::Vector3d V = !c.has("view") ? Eigen::Vector3d::UnitZ()
                                  : is_position(c.at("view"))
                                      ? position(c.at("view"), spec.view_position_mm)
                                      : unit_vector(c.at("view"));
        if (sphere && (V - Eigen::Vector3d::UnitZ()).norm() > 1e-12)
            c.fail_at("view",
                      "a light from a mirror sphere is in the camera's frame: the camera must look "
                      "along the sample's normal (view [0, 0, 1], or no view)");
        for (const auto& [name, v] : {std::pair{"light", L}, std::pair{"view", V}})
            if (!(v.z() > kGrazingCos))
                c.fail_at(name,
                          "points at or below the sample's plane (z ≤ 0, or grazing); the "
                          "normal of the sample is +z");
        const auto g = geometry_from_vectors(Eigen::Vector3d::UnitZ(), L, V);
        if (!g)
            c.fail(
                "the light or the view is at or below the sample's plane (z ≤ 0); the "
                "normal of the sample is +z");
        spec.geometry = *g;
        spec.light = L;
        spec.view = V;
        return degrees(*g);
    }
    if (!c.has("theta_i_deg"))
        c.fail("needs theta_i_deg (and theta_s_deg, phi_s_deg) or light and view");
    // Checked in degrees, as typed (a value converted to radians and back may print differently).
    std::array<double, 3> deg{0.0, 0.0, 0.0};
    const std::array<const char*, 3> names{"theta_i_deg", "theta_s_deg", "phi_s_deg"};
    for (std::size_t a = 0; a < 3; ++a) {
        if (!c.has(names[a])) continue;
        const JsonNode angle = c.at(names[a]);
        deg[a] = angle.number();
        if (a < 2 && !(deg[a] >= 0.0 && deg[a] < 90.0))
            angle.fail(concat(check::format_number(deg[a]), " must be in [0, 90)"));
    }
    Geometry g;
    g.theta_i_rad = deg_to_rad(deg[0]);
    g.theta_s_rad = deg_to_rad(deg[1]);
    g.phi_s_rad = deg_to_rad(deg[2]);
    c.checked([&] { check::geometry(g); });
    spec.geometry = g;
    if (curved) {
        spec.light = light_direction(g);
        spec.view = view_direction(g);
    }
    return deg;
}

// A specular capture is taken in the mirror direction of its light (θs = θi, φs = 0; §4.1.1).
void check_specular_geometry(const JsonNode& c, const CaptureSpec& spec,
                             const std::array<double, 3>& deg) {
    const Geometry& g = spec.geometry;
    if (std::abs(g.theta_i_rad - g.theta_s_rad) <= kSpecularToleranceRad &&
        std::abs(std::remainder(g.phi_s_rad, 2 * kPi)) <= kSpecularToleranceRad)
        return;
    c.fail_at("role",
              concat("a specular capture must be taken in the specular direction (theta_s = "
                     "theta_i, phi_s = 0); got theta_i = ",
                     format_message(deg[0], 15), "°, theta_s = ", format_message(deg[1], 15),
                     "°, phi_s = ", format_message(deg[2], 15), "°"));
}

double tolerance(const JsonNode& j, std::string_view key, double hi, std::string_view unit) {
    return j.at(key).number(0.0, hi, unit);
}

void parse_capture_uncertainty(const JsonNode& j, CaptureTolerances& t) {
    j.only({"angle_deg", "theta_i_deg", "theta_s_deg", "phi_s_deg", "exposure_rel"});
    if (j.has("angle_deg"))
        t.theta_i_deg = t.theta_s_deg = t.phi_s_deg = tolerance(j, "angle_deg", 45.0, "°");
    if (j.has("theta_i_deg")) t.theta_i_deg = tolerance(j, "theta_i_deg", 45.0, "°");
    if (j.has("theta_s_deg")) t.theta_s_deg = tolerance(j, "theta_s_deg", 45.0, "°");
    if (j.has("phi_s_deg")) t.phi_s_deg = tolerance(j, "phi_s_deg", 45.0, "°");
    if (j.has("exposure_rel")) t.exposure_rel = tolerance(j, "exposure_rel", 1.0, "");
}

// "captures": [...] (and the check of "exposures_equal" against the exposures they give).
void parse_captures(const Context& ctx, const JsonNode& doc, bool curved, MeasureRequest& request) {
    if (!doc.has("captures") || !doc.at("captures").is_array() || doc.at("captures").size() == 0)
        doc.fail_at("captures", "must be a non-empty array of captures");
    for (const JsonNode& c : doc.at("captures").array()) {
        c.only({"image", "bracket", "theta_i_deg", "theta_s_deg", "phi_s_deg", "light", "view",
                "exposure_s", "role", "uncertainty", "description"});
        CaptureSpec spec;
        if (request.object.shape == ObjectShape::PhotometricStereo && !c.has("light"))
            c.fail_at("light",
                      "missing: photometric stereo needs each capture's light direction (camera "
                      "frame: x image right, y image up, z toward the camera)");
        if (c.has("image") == c.has("bracket"))
            c.fail("needs \"image\" (a file) or \"bracket\" (an exposure bracket), one of them");
        if (c.has("bracket")) {
            spec.bracket = parse_bracket(ctx, c.at("bracket"));
            spec.image = spec.bracket.front().image;
            if (c.has("exposure_s"))
                c.fail_at("exposure_s",
                          "a bracket gives each photograph's exposure_s; a merged bracket is per "
                          "second");
        } else {
            spec.image = ctx.path(c.at("image"));
        }
        const std::array<double, 3> deg =
            parse_capture_geometry(ctx, c, curved, request.read, spec);
        if (const auto e = c.find("exposure_s")) spec.exposure_s = Context::exposure(*e);
        if (c.has("role")) spec.role = c.at("role").named(parse_capture_role);
        if (c.has("uncertainty")) parse_capture_uncertainty(c.at("uncertainty"), spec.uncertainty);
        if (spec.role == CaptureRole::Specular && !curved) check_specular_geometry(c, spec, deg);
        request.captures.push_back(std::move(spec));
    }
    if (!request.exposures_equal) return;
    // "exposures_equal": true says the exposures are the same: exposure_s values that differ
    // contradict it.
    const CaptureSpec* timed = nullptr;
    for (std::size_t k = 0; k < request.captures.size(); ++k) {
        const CaptureSpec& spec = request.captures[k];
        if (!spec.exposure_s || !spec.bracket.empty()) continue;
        if (timed != nullptr && *timed->exposure_s != *spec.exposure_s)
            doc.fail_at("exposures_equal",
                        concat("true, but captures[", std::to_string(k), "].exposure_s ",
                               check::format_number(*spec.exposure_s), " s differs from ",
                               check::format_number(*timed->exposure_s),
                               " s; give each capture's exposure_s and leave exposures_equal out"));
        if (timed == nullptr) timed = &spec;
    }
}

// The "response" key: a name, {"gamma": g} or {"bracket": [...]}.
void parse_response_key(const Context& ctx, const JsonNode& r, MeasureRequest& request) {
    if (r.is_object() && r.has("bracket")) {
        r.only({"bracket"});
        request.response_bracket = parse_bracket(ctx, r.at("bracket"));
    } else if (r.is_object()) {
        r.only({"gamma", "bracket"});
        if (!r.has("gamma")) r.fail("an object response needs \"gamma\" or \"bracket\"");
        request.read.response = Response::Gamma;
        request.read.gamma = r.at("gamma").positive();
        if (request.read.gamma < 0.1 || request.read.gamma > 10.0)
            r.fail_at("gamma",
                      concat(check::format_number(request.read.gamma), " must be in [0.1, 10]"));
    } else {
        request.read.response = r.named(parse_response);
        if (request.read.response == Response::Gamma) r.fail("give the gamma as {\"gamma\": 2.2}");
    }
}

void parse_highlight(const JsonNode& h, HighlightOptions& o) {
    h.only({"core_radius_px", "annulus_inner_px", "annulus_outer_px", "smoothing_sigma_px",
            "centre_px"});
    if (h.has("core_radius_px")) o.core_radius_px = h.at("core_radius_px").positive();
    if (h.has("annulus_inner_px")) o.annulus_inner_px = h.at("annulus_inner_px").positive();
    if (h.has("annulus_outer_px")) o.annulus_outer_px = h.at("annulus_outer_px").positive();
    if (h.has("smoothing_sigma_px")) o.smoothing_sigma_px = h.at("smoothing_sigma_px").positive();
    if (h.has("centre_px")) {
        const auto c = h.at("centre_px").numbers(2);
        o.centre_px = std::array<double, 2>{c[0], c[1]};
    }
}

void parse_statistics(const JsonNode& s, RegionStatisticsOptions& o) {
    s.only({"tile_size_px", "max_excluded_fraction"});
    if (s.has("tile_size_px")) {
        const JsonNode t = s.at("tile_size_px");
        const double tile = t.positive();
        if (tile != std::floor(tile) || tile > 1e6)
            t.fail("must be a whole number of pixels ≤ 1e6");
        o.tile_size_px = static_cast<std::size_t>(tile);
    }
    if (s.has("max_excluded_fraction")) {
        const JsonNode f = s.at("max_excluded_fraction");
        const double fraction = f.number();
        if (!(fraction >= 0.0 && fraction <= 1.0)) f.fail("must be in [0, 1]");
        o.max_excluded_fraction = fraction;
    }
}

// "uncertainty": the setup's standard uncertainties (k = 1, budget.hpp) and how to propagate
// them; a capture's own "uncertainty" overrides its angles and exposure.
void parse_uncertainty(const JsonNode& j, MeasureRequest& request) {
    j.only({"angle_deg", "exposure_rel", "black_level_dn", "response_gamma", "wavelength_um",
            "flat_field_rel", "very_rough_min_g", "method", "seed", "max_trials"});
    SetupTolerances& t = request.uncertainty;
    if (j.has("angle_deg")) t.angle_deg = tolerance(j, "angle_deg", 45.0, "°");
    if (j.has("exposure_rel")) t.exposure_rel = tolerance(j, "exposure_rel", 1.0, "");
    if (j.has("black_level_dn")) t.black_level_dn = tolerance(j, "black_level_dn", 1e9, " DN");
    if (j.has("response_gamma")) t.response_gamma = tolerance(j, "response_gamma", 5.0, "");
    if (j.has("wavelength_um")) t.wavelength_um = tolerance(j, "wavelength_um", 1.0, " µm");
    if (j.has("flat_field_rel")) t.flat_field_rel = tolerance(j, "flat_field_rel", 1.0, "");
    if (j.has("very_rough_min_g"))
        t.very_rough_min_g = j.at("very_rough_min_g").number(1.0, 1e6, "");
    if (j.has("method"))
        request.propagation.method = j.at("method").named(parse_propagation_method);
    if (j.has("seed"))
        request.propagation.seed =
            static_cast<std::uint64_t>(j.at("seed").integer(0, 9'007'199'254'740'992LL));
    if (j.has("max_trials"))
        request.propagation.max_trials = static_cast<std::size_t>(
            j.at("max_trials")
                .integer(static_cast<long long>(request.propagation.batch_trials), 10'000'000));
}

MeasureRequest parse_document(const io::JsonValue& value, const std::string& path) {
    const JsonNode doc(value, path);
    const Context ctx{std::filesystem::path(path).parent_path()};
    doc.only({"format",
              "version",
              "wavelength_um",
              "channel_wavelengths_um",
              "response",
              "black_level_dn",
              "dark_frame",
              "flat_field",
              "roi",
              "captures",
              "correlation",
              "sigma_um",
              "sigma_um_stderr",
              "R0",
              "factor",
              "radiometry",
              "regime",
              "highlight",
              "statistics",
              "white_balance",
              "object",
              "maps",
              "exposures_equal",
              "uncertainty",
              "black_reference",
              "sample_plane",
              "description"});
    MeasureRequest request;
    request.source = path;
    if (doc.has("format") && doc.at("format").string() != "roughscope-measure")
        doc.fail_at("format", "must be \"roughscope-measure\" when given");
    if (doc.has("wavelength_um")) request.wavelength_um = Context::length(doc.at("wavelength_um"));
    if (doc.has("channel_wavelengths_um")) {
        const JsonNode w = doc.at("channel_wavelengths_um");
        w.numbers(3);  // the shape
        for (std::size_t k = 0; k < 3; ++k)
            request.channel_wavelengths_um[k] = Context::length(w.item(k));
    }
    if (doc.has("exposures_equal")) request.exposures_equal = doc.at("exposures_equal").boolean();
    if (doc.has("response")) parse_response_key(ctx, doc.at("response"), request);
    if (doc.has("black_level_dn")) {
        // One value for every channel, or one per channel ([R, G, B]).
        const JsonNode b = doc.at("black_level_dn");
        std::vector<double> levels =
            b.is_array() ? b.numbers(b.size() == 3 ? 3 : 1) : std::vector<double>{b.number()};
        for (const double level : levels)
            if (level < 0.0) b.fail("must be ≥ 0");
        request.read.black_level_dn = std::move(levels);
    }
    if (doc.has("white_balance")) {
        const JsonNode w = doc.at("white_balance");
        if (!w.json().is_boolean()) w.fail("must be true or false");
        request.read.white_balance = w.boolean();
    }
    if (const auto d = doc.find("dark_frame")) request.dark_frame = ctx.path(*d);
    if (const auto f = doc.find("flat_field")) request.flat_field = ctx.path(*f);
    if (doc.has("correlation"))
        request.correlation = doc.at("correlation").named(parse_correlation);
    if (doc.has("regime")) request.regime = doc.at("regime").named(parse_regime);
    if (doc.has("factor")) request.factor = doc.at("factor").named(parse_geometric_factor);
    if (doc.has("radiometry")) request.radiometry = doc.at("radiometry").named(parse_radiometry);
    if (const auto sigma = doc.find("sigma_um")) request.sigma_um = Context::length(*sigma);
    if (doc.has("sigma_um_stderr"))
        request.sigma_um_stderr = doc.at("sigma_um_stderr").number(0.0, kMaxLengthUm, " µm");
    if (doc.has("R0")) request.R0 = doc.at("R0").positive();
    if (doc.has("highlight")) parse_highlight(doc.at("highlight"), request.highlight);
    if (doc.has("statistics")) parse_statistics(doc.at("statistics"), request.statistics);
    if (doc.has("object")) request.object = parse_object(ctx, doc.at("object"));
    if (doc.has("uncertainty")) parse_uncertainty(doc.at("uncertainty"), request);
    if (doc.has("maps")) request.maps = parse_maps(ctx, doc.at("maps"));
    const bool curved = request.object.shape != ObjectShape::Plane;
    if (doc.has("black_reference"))
        request.black_reference = parse_region(ctx, doc.at("black_reference"));
    if (doc.has("sample_plane")) request.sample_plane = parse_sample_plane(doc.at("sample_plane"));
    if (doc.has("roi"))
        request.roi = parse_region(ctx, doc.at("roi"));
    else if (!curved && !request.maps)
        doc.fail_at("roi",
                    "missing: the region to measure is required (for a flat sample without "
                    "\"maps\")");
    parse_captures(ctx, doc, curved, request);
    return request;
}

}  // namespace

MeasureRequest parse_capture_file(std::string_view text, const std::string& path) {
    const io::JsonValue doc = io::parse_json_text(text, path);
    // Every value is type-checked before it is read; should the JSON library still throw, the
    // file is named as for any other malformed input.
    try {
        return parse_document(doc, path);
    } catch (const io::JsonValue::exception& e) {
        throw DataError(concat(path, ": ", e.what()));
    }
}

MeasureRequest read_capture_file(const std::string& path) {
    const io::JsonValue doc = io::read_json_file(path, "a capture file");
    try {
        return parse_document(doc, path);
    } catch (const io::JsonValue::exception& e) {
        throw DataError(concat(path, ": ", e.what()));
    }
}

}  // namespace roughscope::image
