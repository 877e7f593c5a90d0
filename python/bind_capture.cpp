// roughscope._core: synthetic camera captures (simulation/capture.hpp). render_capture returns
// the images as NumPy arrays and the sidecar dict; write_capture writes the image and the sidecar
// (serialize::write_capture_files, the CLI's code). Keyword arguments mirror the CLI's flags
// (docs/simulation-captures.md, "Python").
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/serialize/capture.hpp"
#include "roughscope/simulation/capture.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

using simulation::CaptureFormat;

const std::set<std::string>& capture_keys() {
    static const std::set<std::string> keys{"scene",
                                            "width",
                                            "height",
                                            "pixel_size_um",
                                            "radius_um",
                                            "theta_i_deg",
                                            "phi_i_deg",
                                            "theta_v_deg",
                                            "phi_v_deg",
                                            "background",
                                            "sigma_over_T",
                                            "T_um",
                                            "correlation",
                                            "model",
                                            "factor",
                                            "wavelength_um",
                                            "oren_nayar_sigma_deg",
                                            "lafortune_n",
                                            "labels",
                                            "brightness",
                                            "electrons_per_unit_s",
                                            "exposure_s",
                                            "gain",
                                            "full_well_e",
                                            "black_level",
                                            "read_noise_e",
                                            "bits",
                                            "response",
                                            "gamma",
                                            "vignetting",
                                            "shot_noise",
                                            "seed",
                                            "keep_geometry"};
    return keys;
}

struct Request {
    serialize::CaptureRecord record;
    simulation::CaptureOptions options;
};

Request request_from(const py::kwargs& kw) {
    for (const auto& item : kw) {
        const auto key = item.first.cast<std::string>();
        if (capture_keys().count(key) == 0)
            throw py::type_error(concat("unexpected keyword argument '", key, "'"));
    }
    // A number given as None is a TypeError (real_scalar, integer_scalar); None means "not
    // given" only for labels and brightness.
    auto has = [&kw](const char* k) { return kw.contains(k); };
    auto has_object = [&kw](const char* k) { return kw.contains(k) && !kw[k].is_none(); };
    auto real = [&](const char* k, double fallback) {
        return has(k) ? real_scalar(k, kw[k]) : fallback;
    };
    auto text = [&](const char* k, const char* fallback) {
        if (!has(k)) return std::string(fallback);
        if (!py::isinstance<py::str>(kw[k])) throw py::type_error(concat(k, " must be a str"));
        return kw[k].cast<std::string>();
    };
    auto flag = [&](const char* k, bool fallback) {
        if (!has(k)) return fallback;
        if (!py::isinstance<py::bool_>(kw[k])) throw py::type_error(concat(k, " must be a bool"));
        return kw[k].cast<bool>();
    };
    Request r;
    simulation::Scene& s = r.record.scene;
    s.shape = simulation::parse_scene_shape(text("scene", "plane"));
    const long long width = has("width") ? integer_scalar("width", kw["width"]) : 256;
    const long long height = has("height") ? integer_scalar("height", kw["height"]) : 256;
    if (width < 1 || width > 65535 || height < 1 || height > 65535)
        throw InvalidArgument(concat("width x height = ", std::to_string(width), " x ",
                                     std::to_string(height),
                                     " is outside the valid range [1, 65535] per side"));
    s.width = static_cast<std::size_t>(width);
    s.height = static_cast<std::size_t>(height);
    s.pixel_size_um = real("pixel_size_um", 10.0);
    s.radius_um = real("radius_um", 0.0);
    for (const char* k : {"theta_i_deg", "theta_v_deg"}) {
        const double t = real(k, 0.0);
        if (!(t >= 0.0 && t < 90.0))
            throw InvalidArgument(
                concat(k, " = ", format_message(t), " is outside the valid range [0, 90) degrees"));
    }
    s.light = simulation::direction_from_angles(deg_to_rad(real("theta_i_deg", 30.0)),
                                                deg_to_rad(real("phi_i_deg", 180.0)));
    s.view = simulation::direction_from_angles(deg_to_rad(real("theta_v_deg", 0.0)),
                                               deg_to_rad(real("phi_v_deg", 0.0)));
    s.background_radiance = real("background", 0.0);

    simulation::SurfaceTruth truth;
    truth.T_um = real("T_um", 5.0);
    truth.correlation = parse_correlation(text("correlation", "gaussian"));
    truth.model = simulation::parse_brightness_model(text("model", "very_rough"));
    truth.factor = parse_geometric_factor(text("factor", "vh"));
    truth.model_options.wavelength_um = real("wavelength_um", 0.555);
    truth.oren_nayar.sigma_rad = deg_to_rad(real("oren_nayar_sigma_deg", 20.0));
    truth.lafortune_n = real("lafortune_n", 1.0);
    // `brightness`: one callable (θi, θs, φs in degrees) → brightness for every label, or a list
    // of callables, one per label (then sigma_over_T is not used).
    auto tabulated = [](py::object f, const char* what) {
        if (!PyCallable_Check(f.ptr()))
            throw py::type_error(concat(what,
                                        " must be a callable (theta_i_deg, theta_s_deg, "
                                        "phi_s_deg) -> float, or a list of them (one per "
                                        "label)"));
        return std::function<double(const Geometry&)>([f](const Geometry& g) {
            py::gil_scoped_acquire gil;
            return f(rad_to_deg(g.theta_i_rad), rad_to_deg(g.theta_s_rad), rad_to_deg(g.phi_s_rad))
                .cast<double>();
        });
    };
    std::vector<std::function<double(const Geometry&)>> per_label;
    if (has_object("brightness")) {
        py::object f = kw["brightness"];
        truth.model = simulation::BrightnessModel::Tabulated;
        if (py::isinstance<py::list>(f) || py::isinstance<py::tuple>(f)) {
            for (py::handle item : f)
                per_label.push_back(
                    tabulated(py::reinterpret_borrow<py::object>(item), "brightness[k]"));
            if (per_label.empty()) throw InvalidArgument("brightness: the list is empty");
        } else {
            truth.tabulated = tabulated(f, "brightness");
        }
    }
    std::vector<double> ratios{0.2};
    if (has("sigma_over_T")) {
        py::array_t<double> a =
            py::array_t<double>::ensure(real_array("sigma_over_T", kw["sigma_over_T"]));
        ratios.assign(a.data(), a.data() + a.size());
        if (ratios.empty()) throw InvalidArgument("sigma_over_T: at least one value is needed");
    }
    for (double ratio : ratios) {
        if (!(ratio > 0.0 && std::isfinite(ratio)))
            throw InvalidArgument(
                concat("sigma_over_T = ", format_message(ratio), " must be finite and > 0"));
    }
    if (!per_label.empty()) {
        for (auto& f : per_label) {
            simulation::SurfaceTruth t = truth;
            t.sigma_um = ratios.front() * truth.T_um;
            t.tabulated = std::move(f);
            r.record.truths.push_back(std::move(t));
        }
    } else {
        for (double ratio : ratios) {
            simulation::SurfaceTruth t = truth;
            t.sigma_um = ratio * truth.T_um;
            r.record.truths.push_back(t);
        }
    }
    const bool several = r.record.truths.size() > 1;
    if (has_object("labels")) {
        auto labels = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>::ensure(
            kw["labels"]);
        if (!labels || labels.ndim() != 2 ||
            static_cast<std::size_t>(labels.shape(0)) != s.height ||
            static_cast<std::size_t>(labels.shape(1)) != s.width)
            throw InvalidArgument(
                concat("labels must be an integer array of shape (height, width) "
                       "= (",
                       std::to_string(s.height), ", ", std::to_string(s.width), ")"));
        r.record.labels.assign(labels.data(), labels.data() + labels.size());
    } else if (several) {
        throw InvalidArgument(
            "sigma_over_T or brightness: several values need labels (an integer array of "
            "shape (height, width) indexing them)");
    }

    simulation::CameraModel& c = r.record.camera;
    c.electrons_per_unit_s = real("electrons_per_unit_s", c.electrons_per_unit_s);
    c.exposure_s = real("exposure_s", c.exposure_s);
    c.gain_dn_per_e = real("gain", c.gain_dn_per_e);
    c.full_well_e = real("full_well_e", c.full_well_e);
    c.black_level_dn = real("black_level", c.black_level_dn);
    c.read_noise_e = real("read_noise_e", c.read_noise_e);
    c.bit_depth = has("bits") ? static_cast<int>(integer_scalar("bits", kw["bits"])) : 14;
    c.response = simulation::parse_response(text("response", "linear"));
    c.gamma = real("gamma", c.gamma);
    c.vignetting = real("vignetting", c.vignetting);
    c.shot_noise = flag("shot_noise", true);
    if (has("seed")) {
        const long long seed = integer_scalar("seed", kw["seed"]);
        if (seed < 0)
            throw InvalidArgument(concat("seed = ", std::to_string(seed), " must be >= 0"));
        c.seed = static_cast<std::uint64_t>(seed);
    }
    r.options.keep_geometry = flag("keep_geometry", true);
    return r;
}

template <class T>
py::array_t<T> image(const std::vector<T>& values, std::size_t h, std::size_t w,
                     std::size_t channels = 1) {
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(h), static_cast<py::ssize_t>(w)};
    if (channels > 1) shape.push_back(static_cast<py::ssize_t>(channels));
    py::array_t<T> out(shape);
    if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
    return out;
}

py::array_t<float> degrees_image(const std::vector<float>& radians, std::size_t h, std::size_t w) {
    py::array_t<float> out = image(radians, h, w);
    float* d = out.mutable_data();
    for (std::size_t i = 0; i < radians.size(); ++i)
        d[i] = static_cast<float>(rad_to_deg(static_cast<double>(d[i])));
    return out;
}

py::dict capture_dict(const simulation::Capture& c, const serialize::CaptureRecord& record,
                      const serialize::Json& sidecar) {
    py::dict out;
    const std::size_t h = c.height, w = c.width;
    out["radiance"] = image(c.radiance, h, w);
    out["expected_dn"] = image(c.expected_dn, h, w);
    out["dn"] = image(c.dn, h, w);
    py::array_t<bool> sat({static_cast<py::ssize_t>(h), static_cast<py::ssize_t>(w)});
    for (std::size_t i = 0; i < c.saturated.size(); ++i)
        sat.mutable_data()[i] = c.saturated[i] != 0;
    out["saturated"] = sat;
    if (!c.label.empty()) {
        out["label"] = image(c.label, h, w);
        out["theta_i_deg"] = degrees_image(c.theta_i_rad, h, w);
        out["theta_s_deg"] = degrees_image(c.theta_s_rad, h, w);
        out["phi_s_deg"] = degrees_image(c.phi_s_rad, h, w);
        out["normal"] = image(c.normal, h, w, 3);
    }
    (void)record;
    out["sidecar"] = to_python(sidecar);
    return out;
}

}  // namespace

void bind_capture(py::module_& m) {
    m.def(
        "render_capture",
        [](const py::kwargs& kw) {
            Request r = request_from(kw);
            simulation::Capture c;
            {
                // The brightness callback re-acquires the GIL; the renderer itself runs without.
                py::gil_scoped_release release;
                c = simulation::render_capture(r.record.scene, r.record.truths, r.record.labels,
                                               r.record.camera, r.options);
            }
            return capture_dict(
                c, r.record, serialize::capture_sidecar(c, r.record, CaptureFormat::Png, "", ""));
        },
        "Render a synthetic capture (keywords as docs/simulation-captures.md, 'Python'). Returns a "
        "dict of (height, width) arrays radiance, expected_dn, dn (uint16), saturated (bool), and "
        "with keep_geometry label, theta_i_deg, theta_s_deg, phi_s_deg, normal (h, w, 3), plus "
        "the sidecar dict.");
    m.def(
        "write_capture",
        [](const std::string& out_dir, const std::string& format, const std::string& stem,
           const py::kwargs& kw) {
            path_argument("out_dir", out_dir);
            Request r = request_from(kw);
            const CaptureFormat f = simulation::parse_capture_format(format);
            // Only what the file and the sidecar need (the same bytes as a full render).
            simulation::CaptureOptions options =
                simulation::capture_options_for_file(f, !r.record.labels.empty());
            options.threads = r.options.threads;
            simulation::Capture c;
            {
                py::gil_scoped_release release;
                c = simulation::render_capture(r.record.scene, r.record.truths, r.record.labels,
                                               r.record.camera, options);
            }
            const serialize::CaptureFiles files = serialize::write_capture_files(
                c, r.record, f, std::filesystem::path(out_dir), stem);
            py::dict out;
            out["image"] = files.image.string();
            out["sidecar"] = files.sidecar.string();
            return out;
        },
        py::arg("out_dir"), py::arg("format") = "png", py::arg("stem") = "capture",
        "Render a capture and write OUT_DIR/<stem>.<ext> + OUT_DIR/<stem>.json (the directory "
        "must exist). Returns the two paths.");
}

}  // namespace roughscope::python
