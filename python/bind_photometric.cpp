// roughscope._core: photometric stereo (objects/photometric_stereo.hpp) — the normals, albedo and
// quality map of an object of unknown shape from photographs under several lights. The scalar
// part of the result is serialize/photometric_stereo.hpp's dict; the per-pixel maps are NumPy
// arrays (docs/photometric-stereo.md).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/response.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/objects/photometric_stereo.hpp"
#include "roughscope/serialize/photometric_stereo.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

std::vector<Eigen::Vector3d> light_rows(py::handle lights) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
        real_array("lights", lights));
    if (!a || a.ndim() != 2 || a.shape(1) != 3)
        throw InvalidArgument("lights must be a (k, 3) array of unit vectors (one per image)");
    std::vector<Eigen::Vector3d> out;
    for (py::ssize_t j = 0; j < a.shape(0); ++j)
        out.emplace_back(a.at(j, 0), a.at(j, 1), a.at(j, 2));
    return out;
}

template <class T>
py::array_t<T> map_array(const std::vector<T>& values, std::size_t height, std::size_t width,
                         std::size_t depth) {
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(height),
                                   static_cast<py::ssize_t>(width)};
    if (depth > 1) shape.push_back(static_cast<py::ssize_t>(depth));
    py::array_t<T> a(shape);
    std::memcpy(a.mutable_data(), values.data(), values.size() * sizeof(T));
    return a;
}

}  // namespace

void bind_photometric_stereo(py::module_& m) {
    m.def(
        "photometric_stereo",
        [](py::handle images, py::handle lights, py::handle mask, const std::string& model,
           py::handle light_intensities, py::handle shadow_fraction, py::handle highlight_fraction,
           const std::optional<std::string>& response, py::handle gamma, py::handle threads) {
            image::ReadOptions read;
            if (response) read.response = parse_response(*response);
            const double gamma_value = real_scalar("gamma", gamma);
            if (read.response == Response::Gamma) read.gamma = gamma_value;
            const std::vector<Eigen::Vector3d> L = light_rows(lights);
            if (!py::isinstance<py::list>(images) && !py::isinstance<py::tuple>(images) &&
                !py::isinstance<py::array>(images))
                throw py::type_error(concat(
                    "images: unsupported type ",
                    py::str(py::type::of(images).attr("__name__")).cast<std::string>(),
                    "; give a list of paths, read_image dicts or arrays of real numbers, one per "
                    "light"));
            if (py::isinstance<py::array>(images)) (void)real_array("images", images);
            std::vector<image::LinearImage> decoded;
            for (py::handle im : images) {
                const bool path = py::isinstance<py::str>(im) || py::hasattr(im, "__fspath__");
                if (path || py::isinstance<py::dict>(im))
                    decoded.push_back(image_argument(im, read, true));
                else
                    decoded.push_back(image_argument(real_array("images", im), read, true));
            }
            std::vector<const image::LinearImage*> pointers;
            pointers.reserve(decoded.size());
            for (const image::LinearImage& im : decoded) pointers.push_back(&im);
            image::PhotometricStereoOptions options;
            options.model = image::parse_photometric_model(model);
            if (!light_intensities.is_none()) {
                const auto e =
                    py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
                        real_array("light_intensities", light_intensities));
                options.light_intensities.assign(e.data(), e.data() + e.size());
            }
            options.shadow_fraction = real_scalar("shadow_fraction", shadow_fraction);
            options.highlight_fraction = real_scalar("highlight_fraction", highlight_fraction);
            const long long t = integer_scalar("threads", threads);
            if (t < 0) throw InvalidArgument("threads must be ≥ 0 (0: every core)");
            options.threads = static_cast<std::size_t>(t);
            std::vector<std::uint8_t> pixels;
            if (!mask.is_none() && !decoded.empty()) {
                const auto a =
                    py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(
                        mask);
                const image::LinearImage& first = decoded.front();
                if (!a || a.ndim() != 2 || static_cast<std::size_t>(a.shape(0)) != first.height ||
                    static_cast<std::size_t>(a.shape(1)) != first.width)
                    throw InvalidArgument(concat("mask must be a (", std::to_string(first.height),
                                                 ", ", std::to_string(first.width),
                                                 ") array (nonzero = on the object)"));
                pixels.assign(a.data(), a.data() + a.size());
            }
            image::PhotometricStereoResult r;
            {
                py::gil_scoped_release release;
                r = image::photometric_stereo(pointers, L, pixels, options);
            }
            py::dict out = to_python(serialize::to_json(r, L));
            out["normals"] = map_array(r.normals, r.height, r.width, 3);
            out["albedo"] = map_array(r.albedo, r.height, r.width, 1);
            out["residual"] = map_array(r.residual, r.height, r.width, 1);
            out["lights_used"] = map_array(r.lights_used, r.height, r.width, 1);
            out["valid"] = py::array(out["lights_used"]).attr("__ge__")(3);
            if (r.model != image::PhotometricModel::Lambert) {
                out["sigma_over_T"] = map_array(r.sigma_over_T, r.height, r.width, 1);
                out["sigma_over_T_stderr"] = map_array(r.sigma_over_T_stderr, r.height, r.width, 1);
                out["delta_aic"] = map_array(r.delta_aic, r.height, r.width, 1);
            }
            return out;
        },
        py::arg("images"), py::arg("lights"), py::arg("mask") = py::none(),
        py::arg("model") = "lambert", py::arg("light_intensities") = py::none(),
        py::arg("shadow_fraction") = 0.05, py::arg("highlight_fraction") = 0.1,
        py::arg("response") = py::none(), py::arg("gamma") = 2.2, py::arg("threads") = 0,
        "Normals and albedo of an object from photographs taken by a fixed camera under lights "
        "from known directions (Lambert's law; docs/photometric-stereo.md). images: one per "
        "light, each a path (read with response/gamma as read_image), read_image's dict, or a "
        "linear (height, width) or (height, width, channels) array; lights: (k, 3) unit "
        "vectors in the camera frame (x right, y up, z towards the camera), k ≥ 3; mask: "
        "(height, width), nonzero on the object; model: \"lambert\", or \"vh_gaussian\" / "
        "\"vh_exponential\" (the very-rough model fitted per pixel with σ/T, k ≥ 4). Returns a "
        "dict: normals (height, width, 3), "
        "albedo, residual (the quality map), lights_used, valid (NaN / False where a pixel has "
        "no normal), and the summary: model, lights, pixels {object, valid, too_few_lights}, "
        "highlights_removed, median_residual, warnings; the rough models add sigma_over_T, "
        "sigma_over_T_stderr and delta_aic (AIC(Lambert) − AIC(rough)) maps, "
        "median_sigma_over_T and model_comparison.");
}

}  // namespace roughscope::python
