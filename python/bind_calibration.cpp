// roughscope._core: calibration of a capture — the light's direction from a photograph of a
// mirror sphere (objects/mirror_sphere.hpp). The result is serialize/calibration.hpp's dict, the
// JSON of `roughscope calibrate light --json` (keys in docs/calibration.md).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/response.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/serialize/calibration.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

// `count` finite reals from a sequence or array of that many (TypeError for non-real values).
std::vector<double> real_list(const char* name, py::handle value, std::size_t count) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
        real_array(name, value));
    if (!a || static_cast<std::size_t>(a.size()) != count || a.ndim() != 1)
        throw InvalidArgument(
            concat(name, " must be a sequence of ", std::to_string(count), " numbers"));
    return {a.data(), a.data() + a.size()};
}

std::vector<std::uint8_t> sphere_mask(py::handle mask, const image::LinearImage& img) {
    const auto m =
        py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(mask);
    if (!m || m.ndim() != 2 || static_cast<std::size_t>(m.shape(0)) != img.height ||
        static_cast<std::size_t>(m.shape(1)) != img.width)
        throw InvalidArgument(concat("mask must be a (", std::to_string(img.height), ", ",
                                     std::to_string(img.width),
                                     ") array (nonzero = on the sphere)"));
    return {m.data(), m.data() + m.size()};
}

}  // namespace

// An image array (height, width) or (channels, height, width) on a linear scale; flags (height,
// width) uint8 or None.
image::LinearImage image_from_array(py::handle values, py::handle flags, bool channels_last) {
    const auto v = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(
        real_array("image", values));
    if (!v || (v.ndim() != 2 && v.ndim() != 3))
        throw InvalidArgument(
            concat("image must be a path, a (height, width) or ",
                   channels_last ? "(height, width, channels)" : "(channels, height, width)",
                   " array, or read_image's dict"));
    image::LinearImage img;
    img.info.source = "array";
    const bool planes = v.ndim() == 3;
    const bool last = planes && channels_last;
    img.channels = planes ? static_cast<std::size_t>(v.shape(last ? 2 : 0)) : 1;
    img.height = static_cast<std::size_t>(v.shape(planes && !last ? 1 : 0));
    img.width = static_cast<std::size_t>(v.shape(planes && !last ? 2 : 1));
    if (last) {  // (height, width, channels) → planar
        const std::size_t n = img.width * img.height;
        img.values.resize(v.size());
        for (std::size_t p = 0; p < n; ++p)
            for (std::size_t c = 0; c < img.channels; ++c)
                img.values[c * n + p] = v.data()[p * img.channels + c];
    } else {
        img.values.assign(v.data(), v.data() + v.size());
    }
    img.flags.assign(img.width * img.height, 0);
    if (!flags.is_none()) {
        const auto f =
            py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(flags);
        if (!f || f.ndim() != 2 || static_cast<std::size_t>(f.shape(0)) != img.height ||
            static_cast<std::size_t>(f.shape(1)) != img.width)
            throw InvalidArgument(concat("flags must be a (", std::to_string(img.height), ", ",
                                         std::to_string(img.width), ") uint8 array"));
        img.flags.assign(f.data(), f.data() + f.size());
    }
    image::check_linear_image(img);
    return img;
}

// A path (str or os.PathLike: read with `read`), read_image's dict, or an array.
image::LinearImage image_argument(py::handle image, const image::ReadOptions& read,
                                  bool channels_last) {
    if (py::isinstance<py::str>(image) || py::hasattr(image, "__fspath__")) {
        const std::string path =
            py::module_::import("os").attr("fspath")(image).cast<std::string>();
        py::gil_scoped_release release;
        return image::read_image(path_argument("image", path), read);
    }
    if (py::isinstance<py::dict>(image)) {
        const py::dict d = py::reinterpret_borrow<py::dict>(image);
        if (!d.contains("values"))
            throw InvalidArgument("image dict must hold 'values' (and 'flags'), as read_image's");
        return image_from_array(d["values"],
                                d.contains("flags") ? py::handle(d["flags"]) : py::none(), false);
    }
    return image_from_array(image, py::none(), channels_last);
}

void bind_calibration(py::module_& m) {
    m.def(
        "calibrate_light",
        [](py::handle image, py::handle circle, py::handle mask, py::handle view,
           py::handle circle_uncertainty_px, const std::optional<std::string>& response,
           py::handle gamma) {
            image::ReadOptions read;
            if (response) read.response = parse_response(*response);
            // Checked whatever the image (as read_image does): used for a path read as gamma.
            const double gamma_value = real_scalar("gamma", gamma);
            if (read.response == Response::Gamma) read.gamma = gamma_value;
            const image::LinearImage img = image_argument(image, read, false);
            std::optional<std::vector<std::uint8_t>> pixels;
            if (!mask.is_none()) pixels = sphere_mask(mask, img);
            image::CircleFit c;
            if (!circle.is_none()) {
                const std::vector<double> v = real_list("circle", circle, 3);
                c.centre_x_px = v[0];
                c.centre_y_px = v[1];
                c.radius_px = v[2];
            } else if (pixels) {
                c = image::circle_from_mask(*pixels, img.width, img.height);
            } else {
                throw InvalidArgument("give the sphere's circle=(cx, cy, r) (px) or its mask");
            }
            image::MirrorSphereOptions options;
            const std::vector<double> v = real_list("view", view, 3);
            options.view = Eigen::Vector3d(v[0], v[1], v[2]);
            options.circle_uncertainty_px =
                real_scalar("circle_uncertainty_px", circle_uncertainty_px);
            serialize::Json doc;
            {
                py::gil_scoped_release release;
                doc = serialize::to_json(
                    image::mirror_sphere_light(img, c, pixels ? &*pixels : nullptr, options),
                    options.circle_uncertainty_px);
            }
            return to_python(doc);
        },
        py::arg("image"), py::arg("circle") = py::none(), py::arg("mask") = py::none(),
        py::arg("view") = py::make_tuple(0.0, 0.0, 1.0), py::arg("circle_uncertainty_px") = 0.5,
        py::arg("response") = py::none(), py::arg("gamma") = 2.2,
        "The light's direction from a photograph of a mirror sphere: image is a path (read with "
        "response/gamma as read_image), read_image's dict, or a linear (height, width) or "
        "(channels, height, width) array; circle = (cx, cy, r) in px (x right, y down, pixel "
        "centres at +0.5), or None with mask (a (height, width) array, nonzero on the sphere, "
        "which also restricts the search). Returns the dict of `roughscope calibrate light "
        "--json`: light [x, y, z] (camera frame: x right, y up, z towards the camera), "
        "theta_deg, phi_deg, angle_uncertainty_deg (k = 1), highlight, circle, pixels, "
        "warnings (docs/calibration.md).");
}

}  // namespace roughscope::python
