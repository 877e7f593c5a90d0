// The capture file of `roughscope measure` (measure.hpp, docs/measure.md): JSON to a
// MeasureRequest. Every key is checked: an unknown key, a wrong type or a value out of range is a
// DataError naming the file and the key.
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/input_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

using Json = nlohmann::json;

// A light or view direction closer to the sample's plane than this cosine is grazing: no
// brightness to measure (scattering/geometry.hpp's horizon).
constexpr double kGrazingCos = 1e-12;

struct Context {
    std::string file;
    std::filesystem::path dir;

    [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
        throw DataError(concat(file, ": ", key, ": ", reason));
    }
    double number(const Json& j, const std::string& key) const {
        if (!j.is_number()) fail(key, concat("must be a number, not ", j.dump()));
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(key, "must be finite");
        return v;
    }
    double positive(const Json& j, const std::string& key) const {
        const double v = number(j, key);
        if (!(v > 0.0)) fail(key, concat(check::format_number(v), " must be > 0"));
        return v;
    }
    // A number in [lo, hi] (`unit` follows the limits in the message).
    double range(const Json& j, const std::string& key, double lo, double hi,
                 std::string_view unit = "") const {
        const double v = number(j, key);
        if (!(v >= lo && v <= hi))
            fail(key, concat(check::format_number(v), " must be in [", check::format_number(lo),
                             ", ", check::format_number(hi), "]", unit));
        return v;
    }
    // An exposure time (s): kMinExposureS … kMaxExposureS (measure.hpp).
    double exposure(const Json& j, const std::string& key) const {
        return range(j, key, kMinExposureS, kMaxExposureS, " s");
    }
    // A length (µm) the scattering functions take: kMinLengthUm … kMaxLengthUm.
    double length(const Json& j, const std::string& key) const {
        return range(j, key, kMinLengthUm, kMaxLengthUm, " µm");
    }
    std::string string(const Json& j, const std::string& key) const {
        if (!j.is_string()) fail(key, concat("must be a string, not ", j.dump()));
        return j.get<std::string>();
    }
    std::string path(const Json& j, const std::string& key) const {
        const std::string p = string(j, key);
        if (p.empty()) fail(key, "must name a file");
        const std::filesystem::path fp(p);
        return (fp.is_absolute() ? fp : dir / fp).lexically_normal().string();
    }
    std::vector<double> numbers(const Json& j, const std::string& key, std::size_t n) const {
        if (!j.is_array() || j.size() != n)
            fail(key,
                 concat("must be an array of ", std::to_string(n), " numbers, not ", j.dump()));
        std::vector<double> out;
        for (std::size_t k = 0; k < n; ++k)
            out.push_back(number(j[k], concat(key, "[", std::to_string(k), "]")));
        return out;
    }
    template <class F>
    auto named(const Json& j, const std::string& key, F parse) const {
        const std::string name = string(j, key);
        try {
            return parse(name);
        } catch (const InvalidArgument& e) {
            fail(key, e.what());
        }
    }
    void only(const Json& object, const std::string& key,
              std::initializer_list<std::string_view> allowed) const {
        if (!object.is_object()) fail(key, concat("must be an object, not ", object.dump()));
        for (const auto& item : object.items()) {
            bool ok = false;
            for (const auto a : allowed) ok = ok || item.key() == a;
            if (!ok) {
                std::string valid;
                for (const auto a : allowed) valid = concat(valid, valid.empty() ? "" : ", ", a);
                fail(concat(key.empty() ? "" : concat(key, "."), item.key()),
                     concat("unknown key; valid keys: ", valid));
            }
        }
    }
};

// A direction: any non-zero vector, normalised (scaled by its largest component first, so that
// neither a huge nor a tiny one overflows or underflows).
Eigen::Vector3d unit_vector(const Context& ctx, const Json& j, const std::string& key) {
    const auto v = ctx.numbers(j, key, 3);
    Eigen::Vector3d d(v[0], v[1], v[2]);
    const double largest = d.cwiseAbs().maxCoeff();
    if (!(largest > 0.0)) ctx.fail(key, "must be a non-zero vector");
    d /= largest;
    return d / d.norm();
}

// [{"image": FILE, "exposure_s": t}, ...]: an exposure bracket (≥ 2 photographs).
std::vector<BracketShot> parse_bracket(const Context& ctx, const Json& j, const std::string& key) {
    if (!j.is_array() || j.size() < 2)
        ctx.fail(key, concat("must be an array of at least 2 {\"image\": FILE, \"exposure_s\": "
                             "t} photographs, not ",
                             j.dump()));
    std::vector<BracketShot> shots;
    for (std::size_t k = 0; k < j.size(); ++k) {
        const std::string name = concat(key, "[", std::to_string(k), "]");
        ctx.only(j[k], name, {"image", "exposure_s"});
        if (!j[k].contains("image") || !j[k].contains("exposure_s"))
            ctx.fail(name, "needs \"image\" and \"exposure_s\"");
        shots.push_back(BracketShot{ctx.path(j[k]["image"], concat(name, ".image")),
                                    ctx.exposure(j[k]["exposure_s"], concat(name, ".exposure_s"))});
    }
    return shots;
}

// {"rect": ...} | {"circle": ...} | {"polygon": ...} | {"mask": FILE}, under `key`; `allowed`
// lists the keys the object may hold (a map region also has its "name").
Region parse_region(const Context& ctx, const Json& j, const std::string& key,
                    std::initializer_list<std::string_view> allowed = {"rect", "circle", "polygon",
                                                                       "mask"}) {
    ctx.only(j, key, allowed);
    const int shapes =
        static_cast<int>(j.contains("rect")) + static_cast<int>(j.contains("circle")) +
        static_cast<int>(j.contains("polygon")) + static_cast<int>(j.contains("mask"));
    if (shapes != 1) ctx.fail(key, "must have exactly one of rect, circle, polygon, mask");
    if (j.contains("rect")) {
        const auto r = ctx.numbers(j["rect"], concat(key, ".rect"), 4);
        return RectangleRegion{r[0], r[1], r[2], r[3]};
    }
    if (j.contains("circle")) {
        const auto c = ctx.numbers(j["circle"], concat(key, ".circle"), 3);
        return CircleRegion{c[0], c[1], c[2]};
    }
    if (j.contains("polygon")) {
        const Json& p = j["polygon"];
        if (!p.is_array()) ctx.fail(concat(key, ".polygon"), "must be an array of [x, y] points");
        std::vector<std::array<double, 2>> points;
        for (std::size_t k = 0; k < p.size(); ++k) {
            const auto xy = ctx.numbers(p[k], concat(key, ".polygon[", std::to_string(k), "]"), 2);
            points.push_back({xy[0], xy[1]});
        }
        return PolygonRegion{points};
    }
    const std::string file = ctx.path(j["mask"], concat(key, ".mask"));
    try {
        return mask_region_from_image(read_image(file));
    } catch (const Error& e) {  // missing, unreadable, not an image
        ctx.fail(concat(key, ".mask"), e.what());
    }
}

// A whole number in [lo, hi].
std::size_t whole(const Context& ctx, const Json& j, const std::string& key, double lo, double hi) {
    const double v = ctx.number(j, key);
    if (v != std::floor(v) || v < lo || v > hi)
        ctx.fail(key, concat(check::format_number(v), " must be a whole number in [",
                             check::format_number(lo), ", ", check::format_number(hi), "]"));
    return static_cast<std::size_t>(v);
}

bool boolean(const Context& ctx, const Json& j, const std::string& key) {
    if (!j.is_boolean()) ctx.fail(key, concat("must be true or false, not ", j.dump()));
    return j.get<bool>();
}

// The library's own check of an options struct, its InvalidArgument reported under `key`.
template <class F>
void checked(const Context& ctx, const std::string& key, F check) {
    try {
        check();
    } catch (const InvalidArgument& e) {
        ctx.fail(key, e.what());
    }
}

EdgePoint point_px(const Context& ctx, const Json& j, const std::string& key) {
    const auto xy = ctx.numbers(j, key, 2);
    EdgePoint p;
    p.x_px = xy[0];
    p.y_px = xy[1];
    return p;
}

void parse_sphere_object(const Context& ctx, const Json& j, SphereOptions& o) {
    ctx.only(j, "object",
             {"shape", "circle", "threshold", "limb_fraction", "max_angle_deg", "cell_px",
              "max_cells", "min_cell_fraction"});
    if (j.contains("circle")) {
        const auto c = ctx.numbers(j["circle"], "object.circle", 3);
        CircleFit circle;
        circle.centre_x_px = c[0];
        circle.centre_y_px = c[1];
        circle.radius_px = c[2];
        if (!(circle.radius_px > 0.0)) ctx.fail("object.circle", "the radius must be > 0");
        o.circle = circle;
    }
    if (j.contains("threshold"))
        o.silhouette.threshold = ctx.positive(j["threshold"], "object.threshold");
    if (j.contains("limb_fraction"))
        o.limb_fraction = ctx.number(j["limb_fraction"], "object.limb_fraction");
    if (j.contains("max_angle_deg"))
        o.max_angle_deg = ctx.number(j["max_angle_deg"], "object.max_angle_deg");
    if (j.contains("cell_px")) o.cell_px = whole(ctx, j["cell_px"], "object.cell_px", 0, 65535);
    if (j.contains("max_cells"))
        o.max_cells = whole(ctx, j["max_cells"], "object.max_cells", 1, 1e7);
    if (j.contains("min_cell_fraction"))
        o.min_cell_fraction = ctx.number(j["min_cell_fraction"], "object.min_cell_fraction");
    checked(ctx, "object", [&] { check_sphere_options(o); });
}

// "object": {"shape": ..., shape options} (docs/measure.md "Curved objects and maps").
ObjectSpec parse_object(const Context& ctx, const Json& j) {
    if (!j.is_object() || !j.contains("shape"))
        ctx.fail("object", concat("must be an object with a \"shape\" (plane, cylinder, sphere, "
                                  "normal_map), not ",
                                  j.dump()));
    ObjectSpec spec;
    spec.shape = ctx.named(j["shape"], "object.shape", parse_object_shape);
    switch (spec.shape) {
        case ObjectShape::Plane:
            ctx.only(j, "object", {"shape"});
            break;
        case ObjectShape::NormalMap:
            ctx.only(j, "object", {"shape", "file"});
            if (!j.contains("file")) ctx.fail("object.file", "missing: the normal-map image");
            spec.normal_map = ctx.path(j["file"], "object.file");
            break;
        case ObjectShape::Cylinder: {
            ctx.only(j, "object",
                     {"shape", "axis", "edges", "half", "bin_width_deg", "min_pixels_per_bin",
                      "limb_fraction", "sigma_over_T", "fit_max_theta_i_deg", "departure_k",
                      "departure_bins", "threshold"});
            CylinderOptions& o = spec.cylinder;
            if (j.contains("axis") && j.contains("edges"))
                ctx.fail("object", "give the cylinder's axis or its edges, not both");
            if (j.contains("axis")) {
                const Json& a = j["axis"];
                ctx.only(a, "object.axis", {"point_px", "direction", "radius_px"});
                if (!a.contains("point_px") || !a.contains("direction") || !a.contains("radius_px"))
                    ctx.fail("object.axis",
                             "needs point_px [x, y], direction [dx, dy] and "
                             "radius_px");
                const auto p = ctx.numbers(a["point_px"], "object.axis.point_px", 2);
                const auto d = ctx.numbers(a["direction"], "object.axis.direction", 2);
                const double r = ctx.positive(a["radius_px"], "object.axis.radius_px");
                checked(ctx, "object.axis",
                        [&] { o.axis = cylinder_axis_from_line(p[0], p[1], d[0], d[1], r); });
            }
            if (j.contains("edges")) {
                const Json& e = j["edges"];
                if (!e.is_array() || e.size() != 2 || !e[0].is_array() || e[0].size() != 2 ||
                    !e[1].is_array() || e[1].size() != 2)
                    ctx.fail("object.edges",
                             "must be two edges of two points each: [[[x, y], [x, y]], "
                             "[[x, y], [x, y]]]");
                const EdgePoint a0 = point_px(ctx, e[0][0], "object.edges[0][0]");
                const EdgePoint a1 = point_px(ctx, e[0][1], "object.edges[0][1]");
                const EdgePoint b0 = point_px(ctx, e[1][0], "object.edges[1][0]");
                const EdgePoint b1 = point_px(ctx, e[1][1], "object.edges[1][1]");
                checked(ctx, "object.edges",
                        [&] { o.axis = cylinder_axis_from_edges(a0, a1, b0, b1); });
            }
            if (j.contains("half"))
                o.half = ctx.named(j["half"], "object.half", parse_cylinder_half);
            if (j.contains("bin_width_deg"))
                o.bin_width_deg = ctx.number(j["bin_width_deg"], "object.bin_width_deg");
            if (j.contains("min_pixels_per_bin"))
                o.min_pixels_per_bin =
                    whole(ctx, j["min_pixels_per_bin"], "object.min_pixels_per_bin", 1, 1e9);
            if (j.contains("limb_fraction"))
                o.limb_fraction = ctx.number(j["limb_fraction"], "object.limb_fraction");
            if (j.contains("sigma_over_T") && !j["sigma_over_T"].is_null())
                o.sigma_over_T = ctx.positive(j["sigma_over_T"], "object.sigma_over_T");
            if (j.contains("fit_max_theta_i_deg"))
                o.fit_max_theta_i_deg =
                    ctx.number(j["fit_max_theta_i_deg"], "object.fit_max_theta_i_deg");
            if (j.contains("departure_k"))
                o.departure_k = ctx.number(j["departure_k"], "object.departure_k");
            if (j.contains("departure_bins"))
                o.departure_bins = whole(ctx, j["departure_bins"], "object.departure_bins", 1, 1e6);
            if (j.contains("threshold"))
                o.silhouette.threshold = ctx.positive(j["threshold"], "object.threshold");
            checked(ctx, "object", [&] { check_cylinder_options(o); });
            break;
        }
        case ObjectShape::Sphere:
            parse_sphere_object(ctx, j, spec.sphere);
            break;
    }
    return spec;
}

// "maps": {...} (docs/measure.md "Curved objects and maps", docs/maps.md).
MapRequest parse_maps(const Context& ctx, const Json& j) {
    ctx.only(j, "maps",
             {"window_px", "min_used_fraction", "max_shift_px", "allow_misregistration",
              "slightly_rough_max_sigma_over_T", "very_rough_min_sigma_over_T", "both_correlations",
              "ratio_layer", "regions"});
    MapRequest maps;
    MapOptions& o = maps.options;
    if (j.contains("window_px"))
        o.window_px = whole(ctx, j["window_px"], "maps.window_px", 1, 4096);
    if (j.contains("min_used_fraction")) {
        o.min_used_fraction = ctx.number(j["min_used_fraction"], "maps.min_used_fraction");
        if (!(o.min_used_fraction > 0.0 && o.min_used_fraction <= 1.0))
            ctx.fail("maps.min_used_fraction",
                     concat(check::format_number(o.min_used_fraction), " must be in (0, 1]"));
    }
    if (j.contains("max_shift_px")) {
        o.max_shift_px = ctx.number(j["max_shift_px"], "maps.max_shift_px");
        if (o.max_shift_px < 0.0) ctx.fail("maps.max_shift_px", "must be ≥ 0");
    }
    if (j.contains("allow_misregistration"))
        o.allow_misregistration =
            boolean(ctx, j["allow_misregistration"], "maps.allow_misregistration");
    if (j.contains("both_correlations"))
        o.both_correlations = boolean(ctx, j["both_correlations"], "maps.both_correlations");
    if (j.contains("ratio_layer"))
        o.ratio_layer = boolean(ctx, j["ratio_layer"], "maps.ratio_layer");
    if (j.contains("slightly_rough_max_sigma_over_T"))
        o.slightly_rough_max_sigma_over_T = ctx.positive(j["slightly_rough_max_sigma_over_T"],
                                                         "maps.slightly_rough_max_sigma_over_T");
    if (j.contains("very_rough_min_sigma_over_T"))
        o.very_rough_min_sigma_over_T =
            ctx.positive(j["very_rough_min_sigma_over_T"], "maps.very_rough_min_sigma_over_T");
    if (!(o.very_rough_min_sigma_over_T >= o.slightly_rough_max_sigma_over_T))
        ctx.fail(j.contains("very_rough_min_sigma_over_T") ? "maps.very_rough_min_sigma_over_T"
                                                           : "maps.slightly_rough_max_sigma_over_T",
                 concat("very_rough_min_sigma_over_T = ",
                        check::format_number(o.very_rough_min_sigma_over_T),
                        " must be at least slightly_rough_max_sigma_over_T = ",
                        check::format_number(o.slightly_rough_max_sigma_over_T)));
    if (j.contains("regions")) {
        const Json& r = j["regions"];
        if (!r.is_array())
            ctx.fail("maps.regions", "must be an array of {\"name\": ..., \"rect\": ...} regions");
        for (std::size_t k = 0; k < r.size(); ++k) {
            const std::string key = concat("maps.regions[", std::to_string(k), "]");
            if (!r[k].is_object() || !r[k].contains("name"))
                ctx.fail(key, "needs a \"name\" and one of rect, circle, polygon, mask");
            const std::string name = ctx.string(r[k]["name"], concat(key, ".name"));
            maps.regions.emplace_back(
                name, parse_region(ctx, r[k], key, {"name", "rect", "circle", "polygon", "mask"}));
        }
    }
    return maps;
}

// The capture's geometry: theta_i_deg, theta_s_deg, phi_s_deg (paper frame) or light and view
// vectors (the sample's normal +z; for a curved object the camera frame, view +z by default, and
// neither given: L = V = +z, the retro-reflection of §5.2). Returns (θi, θs, φs) in degrees as
// typed (from vectors: as computed), for messages that echo them.
std::array<double, 3> parse_capture_geometry(const Context& ctx, const Json& c,
                                             const std::string& key, bool curved,
                                             CaptureSpec& spec) {
    const bool angles =
        c.contains("theta_i_deg") || c.contains("theta_s_deg") || c.contains("phi_s_deg");
    const bool vectors = c.contains("light") || c.contains("view");
    if (angles && vectors)
        ctx.fail(key,
                 "give either theta_i_deg, theta_s_deg, phi_s_deg or light and view, not both");
    auto degrees = [](const Geometry& g) {
        return std::array<double, 3>{rad_to_deg(g.theta_i_rad), rad_to_deg(g.theta_s_rad),
                                     rad_to_deg(g.phi_s_rad)};
    };
    if (curved && !angles) {
        spec.light = c.contains("light") ? unit_vector(ctx, c["light"], concat(key, ".light"))
                                         : Eigen::Vector3d::UnitZ();
        spec.view = c.contains("view") ? unit_vector(ctx, c["view"], concat(key, ".view"))
                                       : Eigen::Vector3d::UnitZ();
        for (const auto& [name, v] :
             {std::pair{"light", *spec.light}, std::pair{"view", *spec.view}})
            if (!(v.z() > kGrazingCos))
                ctx.fail(concat(key, ".", name),
                         "must point toward the camera side (z > 0; camera frame: x image right, "
                         "y image up, z toward the camera)");
        if (const auto g = geometry_from_vectors(Eigen::Vector3d::UnitZ(), *spec.light, *spec.view))
            spec.geometry = *g;
        return degrees(spec.geometry);
    }
    if (vectors) {
        if (!c.contains("light") || !c.contains("view"))
            ctx.fail(key, "light and view must both be given");
        const Eigen::Vector3d L = unit_vector(ctx, c["light"], concat(key, ".light"));
        const Eigen::Vector3d V = unit_vector(ctx, c["view"], concat(key, ".view"));
        for (const auto& [name, v] : {std::pair{"light", L}, std::pair{"view", V}})
            if (!(v.z() > kGrazingCos))
                ctx.fail(concat(key, ".", name),
                         "points at or below the sample's plane (z ≤ 0, or grazing); the "
                         "normal of the sample is +z");
        const auto g = geometry_from_vectors(Eigen::Vector3d::UnitZ(), L, V);
        if (!g)
            ctx.fail(key,
                     "the light or the view is at or below the sample's plane (z ≤ 0); the "
                     "normal of the sample is +z");
        spec.geometry = *g;
        spec.light = L;
        spec.view = V;
        return degrees(*g);
    }
    if (!c.contains("theta_i_deg"))
        ctx.fail(key, "needs theta_i_deg (and theta_s_deg, phi_s_deg) or light and view");
    // Checked in degrees, as typed (a value converted to radians and back may print differently).
    std::array<double, 3> deg{0.0, 0.0, 0.0};
    const std::array<const char*, 3> names{"theta_i_deg", "theta_s_deg", "phi_s_deg"};
    for (std::size_t a = 0; a < 3; ++a) {
        if (!c.contains(names[a])) continue;
        const std::string name = concat(key, ".", names[a]);
        deg[a] = ctx.number(c[names[a]], name);
        if (a < 2 && !(deg[a] >= 0.0 && deg[a] < 90.0))
            ctx.fail(name, concat(check::format_number(deg[a]), " must be in [0, 90)"));
    }
    Geometry g;
    g.theta_i_rad = deg_to_rad(deg[0]);
    g.theta_s_rad = deg_to_rad(deg[1]);
    g.phi_s_rad = deg_to_rad(deg[2]);
    checked(ctx, key, [&] { check::geometry(g); });
    spec.geometry = g;
    if (curved) {
        spec.light = light_direction(g);
        spec.view = view_direction(g);
    }
    return deg;
}

// A specular capture is taken in the mirror direction of its light (θs = θi, φs = 0; §4.1.1).
void check_specular_geometry(const Context& ctx, const CaptureSpec& spec, const std::string& key,
                             const std::array<double, 3>& deg) {
    const Geometry& g = spec.geometry;
    if (std::abs(g.theta_i_rad - g.theta_s_rad) <= kSpecularToleranceRad &&
        std::abs(std::remainder(g.phi_s_rad, 2 * kPi)) <= kSpecularToleranceRad)
        return;
    ctx.fail(concat(key, ".role"),
             concat("a specular capture must be taken in the specular direction (theta_s = "
                    "theta_i, phi_s = 0); got theta_i = ",
                    format_message(deg[0], 15), "°, theta_s = ", format_message(deg[1], 15),
                    "°, phi_s = ", format_message(deg[2], 15), "°"));
}

// "captures": [...] (and the check of "exposures_equal" against the exposures they give).
void parse_captures(const Context& ctx, const Json& doc, bool curved, MeasureRequest& request) {
    if (!doc.contains("captures") || !doc["captures"].is_array() || doc["captures"].empty())
        ctx.fail("captures", "must be a non-empty array of captures");
    const Json& captures = doc["captures"];
    for (std::size_t k = 0; k < captures.size(); ++k) {
        const std::string key = concat("captures[", std::to_string(k), "]");
        const Json& c = captures[k];
        ctx.only(c, key,
                 {"image", "bracket", "theta_i_deg", "theta_s_deg", "phi_s_deg", "light", "view",
                  "exposure_s", "role", "description"});
        CaptureSpec spec;
        if (c.contains("image") == c.contains("bracket"))
            ctx.fail(key,
                     "needs \"image\" (a file) or \"bracket\" (an exposure bracket), one of them");
        if (c.contains("bracket")) {
            spec.bracket = parse_bracket(ctx, c["bracket"], concat(key, ".bracket"));
            spec.image = spec.bracket.front().image;
            if (c.contains("exposure_s"))
                ctx.fail(concat(key, ".exposure_s"),
                         "a bracket gives each photograph's exposure_s; a merged bracket is per "
                         "second");
        } else {
            spec.image = ctx.path(c["image"], concat(key, ".image"));
        }
        const std::array<double, 3> deg = parse_capture_geometry(ctx, c, key, curved, spec);
        if (c.contains("exposure_s") && !c["exposure_s"].is_null())
            spec.exposure_s = ctx.exposure(c["exposure_s"], concat(key, ".exposure_s"));
        if (c.contains("role"))
            spec.role = ctx.named(c["role"], concat(key, ".role"), parse_capture_role);
        if (spec.role == CaptureRole::Specular && !curved)
            check_specular_geometry(ctx, spec, key, deg);
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
            ctx.fail("exposures_equal",
                     concat("true, but captures[", std::to_string(k), "].exposure_s ",
                            check::format_number(*spec.exposure_s), " s differs from ",
                            check::format_number(*timed->exposure_s),
                            " s; give each capture's exposure_s and leave exposures_equal out"));
        if (timed == nullptr) timed = &spec;
    }
}

}  // namespace

namespace {

MeasureRequest parse_checked(std::string_view text, const std::string& path);

}  // namespace

MeasureRequest parse_capture_file(std::string_view text, const std::string& path) {
    // Every value is type-checked before it is read; should the JSON library still throw, the
    // file is named as for any other malformed input.
    try {
        return parse_checked(text, path);
    } catch (const Json::exception& e) {
        throw DataError(concat(path, ": ", e.what()));
    }
}

namespace {

MeasureRequest parse_checked(std::string_view text, const std::string& path) {
    Context ctx{path, std::filesystem::path(path).parent_path()};
    Json doc;
    try {
        doc = Json::parse(text);
    } catch (const Json::exception& e) {  // a syntax error or a number out of range
        throw DataError(concat(path, ": not valid JSON: ", e.what()));
    }
    ctx.only(doc, "",
             {"format",
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
              "description"});
    MeasureRequest request;
    request.source = path;
    if (doc.contains("format") && ctx.string(doc["format"], "format") != "roughscope-measure")
        ctx.fail("format", "must be \"roughscope-measure\" when given");
    if (doc.contains("wavelength_um"))
        request.wavelength_um = ctx.length(doc["wavelength_um"], "wavelength_um");
    if (doc.contains("channel_wavelengths_um")) {
        const Json& w = doc["channel_wavelengths_um"];
        ctx.numbers(w, "channel_wavelengths_um", 3);  // the shape
        for (std::size_t k = 0; k < 3; ++k)
            request.channel_wavelengths_um[k] =
                ctx.length(w[k], concat("channel_wavelengths_um[", std::to_string(k), "]"));
    }
    if (doc.contains("exposures_equal"))
        request.exposures_equal = boolean(ctx, doc["exposures_equal"], "exposures_equal");
    if (doc.contains("response")) {
        const Json& r = doc["response"];
        if (r.is_object() && r.contains("bracket")) {
            ctx.only(r, "response", {"bracket"});
            request.response_bracket = parse_bracket(ctx, r["bracket"], "response.bracket");
        } else if (r.is_object()) {
            ctx.only(r, "response", {"gamma", "bracket"});
            if (!r.contains("gamma"))
                ctx.fail("response", "an object response needs \"gamma\" or \"bracket\"");
            request.read.response = Response::Gamma;
            request.read.gamma = ctx.positive(r["gamma"], "response.gamma");
            if (request.read.gamma < 0.1 || request.read.gamma > 10.0)
                ctx.fail("response.gamma",
                         concat(check::format_number(request.read.gamma), " must be in [0.1, 10]"));
        } else {
            request.read.response = ctx.named(r, "response", parse_response);
            if (request.read.response == Response::Gamma)
                ctx.fail("response", "give the gamma as {\"gamma\": 2.2}");
        }
    }
    if (doc.contains("black_level_dn")) {
        // One value for every channel, or one per channel ([R, G, B]).
        const Json& b = doc["black_level_dn"];
        std::vector<double> levels = b.is_array()
                                         ? ctx.numbers(b, "black_level_dn", b.size() == 3 ? 3 : 1)
                                         : std::vector<double>{ctx.number(b, "black_level_dn")};
        for (const double level : levels)
            if (level < 0.0) ctx.fail("black_level_dn", "must be ≥ 0");
        request.read.black_level_dn = std::move(levels);
    }
    if (doc.contains("white_balance")) {
        if (!doc["white_balance"].is_boolean()) ctx.fail("white_balance", "must be true or false");
        request.read.white_balance = doc["white_balance"].get<bool>();
    }
    if (doc.contains("dark_frame") && !doc["dark_frame"].is_null())
        request.dark_frame = ctx.path(doc["dark_frame"], "dark_frame");
    if (doc.contains("flat_field") && !doc["flat_field"].is_null())
        request.flat_field = ctx.path(doc["flat_field"], "flat_field");
    if (doc.contains("correlation"))
        request.correlation = ctx.named(doc["correlation"], "correlation", parse_correlation);
    if (doc.contains("regime")) request.regime = ctx.named(doc["regime"], "regime", parse_regime);
    if (doc.contains("factor"))
        request.factor = ctx.named(doc["factor"], "factor", parse_geometric_factor);
    if (doc.contains("radiometry"))
        request.radiometry = ctx.named(doc["radiometry"], "radiometry", parse_radiometry);
    if (doc.contains("sigma_um") && !doc["sigma_um"].is_null())
        request.sigma_um = ctx.length(doc["sigma_um"], "sigma_um");
    if (doc.contains("sigma_um_stderr"))
        request.sigma_um_stderr =
            ctx.range(doc["sigma_um_stderr"], "sigma_um_stderr", 0.0, kMaxLengthUm, " µm");
    if (doc.contains("R0")) request.R0 = ctx.positive(doc["R0"], "R0");
    if (doc.contains("highlight")) {
        const Json& h = doc["highlight"];
        ctx.only(h, "highlight",
                 {"core_radius_px", "annulus_inner_px", "annulus_outer_px", "smoothing_sigma_px",
                  "centre_px"});
        if (h.contains("core_radius_px"))
            request.highlight.core_radius_px =
                ctx.positive(h["core_radius_px"], "highlight.core_radius_px");
        if (h.contains("annulus_inner_px"))
            request.highlight.annulus_inner_px =
                ctx.positive(h["annulus_inner_px"], "highlight.annulus_inner_px");
        if (h.contains("annulus_outer_px"))
            request.highlight.annulus_outer_px =
                ctx.positive(h["annulus_outer_px"], "highlight.annulus_outer_px");
        if (h.contains("smoothing_sigma_px"))
            request.highlight.smoothing_sigma_px =
                ctx.positive(h["smoothing_sigma_px"], "highlight.smoothing_sigma_px");
        if (h.contains("centre_px")) {
            const auto c = ctx.numbers(h["centre_px"], "highlight.centre_px", 2);
            request.highlight.centre_px = std::array<double, 2>{c[0], c[1]};
        }
    }
    if (doc.contains("statistics")) {
        const Json& s = doc["statistics"];
        ctx.only(s, "statistics", {"tile_size_px", "max_excluded_fraction"});
        if (s.contains("tile_size_px")) {
            const double t = ctx.positive(s["tile_size_px"], "statistics.tile_size_px");
            if (t != std::floor(t) || t > 1e6)
                ctx.fail("statistics.tile_size_px", "must be a whole number of pixels ≤ 1e6");
            request.statistics.tile_size_px = static_cast<std::size_t>(t);
        }
        if (s.contains("max_excluded_fraction")) {
            const double f =
                ctx.number(s["max_excluded_fraction"], "statistics.max_excluded_fraction");
            if (!(f >= 0.0 && f <= 1.0))
                ctx.fail("statistics.max_excluded_fraction", "must be in [0, 1]");
            request.statistics.max_excluded_fraction = f;
        }
    }
    if (doc.contains("object")) request.object = parse_object(ctx, doc["object"]);
    if (doc.contains("maps")) request.maps = parse_maps(ctx, doc["maps"]);
    const bool curved = request.object.shape != ObjectShape::Plane;
    if (doc.contains("roi"))
        request.roi = parse_region(ctx, doc["roi"], "roi");
    else if (!curved && !request.maps)
        ctx.fail("roi",
                 "missing: the region to measure is required (for a flat sample without "
                 "\"maps\")");
    parse_captures(ctx, doc, curved, request);
    return request;
}

}  // namespace

MeasureRequest read_capture_file(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw DataError(concat(path, ": is a directory, not a capture file"));
    io::check_input_file(path, path);
    constexpr std::size_t kMaxCaptureFileBytes = std::size_t{16} << 20;
    const auto too_large = [&] {
        return DataError(concat(path, ": larger than 16 MiB: not a capture file"));
    };
    std::error_code size_ec;
    if (std::filesystem::file_size(path, size_ec) > kMaxCaptureFileBytes && !size_ec)
        throw too_large();
    std::ifstream in(path, std::ios::binary);
    if (!in) throw DataError(concat(path, ": cannot open the capture file"));
    std::ostringstream text;
    text << in.rdbuf();
    if (text.str().size() > kMaxCaptureFileBytes) throw too_large();
    return parse_capture_file(text.str(), path);
}

}  // namespace roughscope::image
