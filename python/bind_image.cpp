// roughscope._core: photographs to roughness (image/*.hpp). Thin and vectorised: images cross as
// NumPy arrays (values (channels, height, width) float32, flags (height, width) uint8), results
// as the serializer's dicts (serialize/measure.hpp, the CLI's JSON). Keys in docs/measure.md.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/region/region.hpp"
#include "roughscope/region/statistics.hpp"
#include "roughscope/serialize/measure.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

py::dict image_dict(const image::LinearImage& image) {
    py::array_t<float> values({image.channels, image.height, image.width});
    std::memcpy(values.mutable_data(), image.values.data(), image.values.size() * sizeof(float));
    py::array_t<std::uint8_t> flags({image.height, image.width});
    std::memcpy(flags.mutable_data(), image.flags.data(), image.flags.size());
    py::dict out;
    out["values"] = values;
    out["flags"] = flags;
    out["info"] = to_python(serialize::to_json(image.info));  // the CLI's `info` of a capture
    return out;
}

image::ReadOptions read_options(const std::optional<std::string>& response, py::handle gamma,
                                py::handle black_level_dn, bool white_balance) {
    image::ReadOptions options;
    if (response) options.response = parse_response(*response);
    if (options.response == Response::Gamma) options.gamma = real_scalar("gamma", gamma);
    if (const auto black = optional_real("black_level_dn", black_level_dn))
        options.black_level_dn = std::vector<double>{*black};
    options.white_balance = white_balance;
    return options;
}

// A LinearImage from NumPy: values (channels, height, width) or (height, width), flags (height,
// width) or None (no pixel flagged).
image::LinearImage linear_image_from(py::handle values, py::handle flags) {
    auto v = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(
        real_array("values", values));
    if (!v) throw InvalidArgument("values must be a real array of shape (channels, height, width)");
    image::LinearImage image;
    image.info.source = "array";
    if (v.ndim() == 2) {
        image.channels = 1;
        image.height = static_cast<std::size_t>(v.shape(0));
        image.width = static_cast<std::size_t>(v.shape(1));
    } else if (v.ndim() == 3) {
        image.channels = static_cast<std::size_t>(v.shape(0));
        image.height = static_cast<std::size_t>(v.shape(1));
        image.width = static_cast<std::size_t>(v.shape(2));
    } else {
        throw InvalidArgument(concat("values has ", std::to_string(v.ndim()),
                                     " dimensions; valid: (height, width) or (channels, height, "
                                     "width)"));
    }
    image.values.assign(v.data(), v.data() + v.size());
    if (flags.is_none()) {
        image.flags.assign(image.width * image.height, 0);
    } else {
        auto f =
            py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(flags);
        if (!f || f.ndim() != 2 || static_cast<std::size_t>(f.shape(0)) != image.height ||
            static_cast<std::size_t>(f.shape(1)) != image.width)
            throw InvalidArgument(concat("flags must be a (", std::to_string(image.height), ", ",
                                         std::to_string(image.width),
                                         ") array of pixel flags (uint8)"));
        image.flags.assign(f.data(), f.data() + f.size());
    }
    image::check_linear_image(image);
    return image;
}

// A count (≥ 1, or ≥ 0 when zero_ok) from a Python integer; bool, float and str are refused.
std::size_t size_of(const char* name, py::handle value, bool zero_ok = false) {
    const long long n = integer_scalar(name, value);
    if (n < (zero_ok ? 0 : 1) || n > (1LL << 31))
        throw InvalidArgument(concat(name, " = ", std::to_string(n), " must be in [",
                                     zero_ok ? "0" : "1", ", 2^31]"));
    return static_cast<std::size_t>(n);
}

std::vector<std::uint8_t> mask_from(py::handle mask, std::size_t height, std::size_t width) {
    auto m = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(mask);
    if (!m || m.ndim() != 2 || static_cast<std::size_t>(m.shape(0)) != height ||
        static_cast<std::size_t>(m.shape(1)) != width)
        throw InvalidArgument(concat("mask must be a (", std::to_string(height), ", ",
                                     std::to_string(width), ") array (nonzero = in the region)"));
    return {m.data(), m.data() + m.size()};
}

}  // namespace

void bind_image(py::module_& m) {
    m.def(
        "read_image",
        [](const std::string& path, const std::optional<std::string>& response, py::handle gamma,
           py::handle black_level_dn, bool white_balance) {
            const auto options = read_options(response, gamma, black_level_dn, white_balance);
            image::LinearImage image;
            {
                py::gil_scoped_release release;
                image = image::read_image(path_argument("path", path), options);
            }
            return image_dict(image);
        },
        py::arg("path"), py::arg("response") = py::none(), py::arg("gamma") = 2.2,
        py::arg("black_level_dn") = py::none(), py::arg("white_balance") = false,
        "Reads a photograph (PNG, TIFF, JPEG, camera RAW) on a linear scale (response None: what "
        "the file says; 'linear', 'srgb' or 'gamma' with gamma): a dict with values "
        "(channels, height, width) float32, flags (height, width) uint8 (1 saturated, 2 clipped "
        "low, 4 no flat field, 8 missing: NaN in a float file) and info (docs/image.md).");
    m.def(
        "region_mask",
        [](const py::dict& roi, py::handle width_in, py::handle height_in) {
            const auto width = size_of("width", width_in);
            const auto height = size_of("height", height_in);
            // The roi dict of the capture file ({"rect": [...]} etc.), parsed by the library.
            const std::string text =
                concat(R"({"roi": )", serialize::dump(from_python(roi, "roi"), -1),
                       R"(, "captures": [{"image": "unused", "theta_i_deg": 0}]})");
            const image::MeasureRequest request = image::parse_capture_file(text, "roi");
            const std::vector<std::uint8_t> mask = image::rasterize(*request.roi, width, height);
            py::array_t<bool> out({height, width});
            auto* dst = out.mutable_data();
            for (std::size_t k = 0; k < mask.size(); ++k) dst[k] = mask[k] != 0;
            return out;
        },
        py::arg("roi"), py::arg("width"), py::arg("height"),
        "The pixels of a region ({'rect': [x, y, w, h]}, {'circle': [cx, cy, r]}, {'polygon': "
        "[[x, y], ...]}) of a width x height image: a (height, width) bool array.");
    m.def(
        "region_statistics",
        [](py::handle values, py::handle mask, py::handle flags, py::handle tile_size_px,
           py::handle max_excluded_fraction) {
            const image::LinearImage image = linear_image_from(values, flags);
            const auto pixels = mask_from(mask, image.height, image.width);
            image::RegionStatisticsOptions options;
            options.tile_size_px = size_of("tile_size_px", tile_size_px, true);
            options.max_excluded_fraction =
                real_scalar("max_excluded_fraction", max_excluded_fraction);
            return to_python(serialize::to_json(image::region_statistics(image, pixels, options)));
        },
        py::arg("values"), py::arg("mask"), py::arg("flags") = py::none(),
        py::arg("tile_size_px") = 0, py::arg("max_excluded_fraction") = 0.5,
        "Mean, robust mean, std and the two standard errors (pixel noise, tiles) of a region, "
        "per channel and for the channel average (docs/image-regions.md).");
    m.def(
        "measure",
        [](const std::string& capture_file, bool layers) {
            serialize::Json doc;
            std::optional<image::RoughnessMap> map;
            {
                py::gil_scoped_release release;
                const image::MeasureRequest request =
                    image::read_capture_file(path_argument("capture_file", capture_file));
                image::MeasureResult result = image::measure(request);
                doc = serialize::to_json(result, request);
                if (layers) map = std::move(result.map);
            }
            py::dict out = to_python(doc).cast<py::dict>();
            if (map) {
                // The map's layers as (height, width) arrays, named as the CLI's files.
                py::dict arrays;
                const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(map->height),
                                                     static_cast<py::ssize_t>(map->width)};
                for (const auto& layer : serialize::map_float_layers(*map))
                    arrays[py::str(layer.name)] = py::array_t<float>(shape, layer.values->data());
                for (const auto& layer : serialize::map_class_layers(*map))
                    arrays[py::str(layer.name)] =
                        py::array_t<std::uint8_t>(shape, layer.values->data());
                out["map"].cast<py::dict>()["layers"] = arrays;
            }
            return out;
        },
        py::arg("capture_file"), py::arg("layers") = false,
        "Roughness from the photographs named in a capture file (JSON): the dict of "
        "`roughscope measure --json` (docs/measure.md); layers=True adds the roughness map's "
        "layers as (height, width) arrays under result['map']['layers'], named as the files of "
        "`roughscope measure --maps` (result['map']['layer_names']).");
}

}  // namespace roughscope::python
