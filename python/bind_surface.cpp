// Python bindings of the surface topic (surface/*.hpp): height files, statistics, generation and
// the bridge to the optics, with NumPy arrays in and out.
//
// Conventions (docs/python.md): heights are a 2-D float64 array of shape (ny, nx) in µm — row iy
// is y = iy·dy — with NaN for a missing point; a 1-D array is a profile (ny = 1). The statistics
// and the prediction are the library's serializer documents (roughscope/serialize/surface.hpp),
// the same as `roughscope surface stats|predict --json`, as Python objects. Non-real input raises
// TypeError naming the argument; a bad value raises a roughscope.Error (ValueError).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/surface.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/generate.hpp"
#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/predict.hpp"
#include "roughscope/surface/statistics.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A (ny, nx) float64 array of the map's heights (a copy; NaN = missing).
py::array_t<double> heights_array(const surface::HeightMap& map) {
    check_allocation(static_cast<double>(map.size()), 1, "the height array");
    py::array_t<double> out({static_cast<py::ssize_t>(map.ny), static_cast<py::ssize_t>(map.nx)});
    if (map.size() > 0)
        std::memcpy(out.mutable_data(), map.heights_um.data(), map.size() * sizeof(double));
    return out;
}

}  // namespace

surface::HeightMap height_map_from(py::handle heights, py::handle dx, py::handle dy) {
    const double dx_um = real_scalar("dx_um", dx);
    const std::optional<double> dy_um = optional_real("dy_um", dy);
    const auto a = DoubleArray::ensure(real_array("heights_um", heights));
    if (!a) throw py::error_already_set();
    if (a.ndim() != 1 && a.ndim() != 2)
        throw InvalidArgument("heights_um must be a 1-D profile or a 2-D (ny, nx) array, got " +
                              std::to_string(a.ndim()) + " dimensions");
    const std::size_t ny = a.ndim() == 2 ? static_cast<std::size_t>(a.shape(0)) : 1;
    const std::size_t nx = static_cast<std::size_t>(a.ndim() == 2 ? a.shape(1) : a.shape(0));
    surface::HeightMap map = surface::make_height_map(nx, ny, dx_um, dy_um.value_or(dx_um));
    if (map.size() > 0) std::memcpy(map.heights_um.data(), a.data(), map.size() * sizeof(double));
    // Infinities are missing points too (height_map.hpp); the library keeps NaN only.
    for (double& z : map.heights_um)
        if (!std::isfinite(z)) z = std::numeric_limits<double>::quiet_NaN();
    surface::validate(map, "heights_um");
    return map;
}

namespace {

surface::RawSampleType raw_type_of(const std::string& name) {
    const std::string n = normalize_name(name);
    if (n == "float32" || n == "f32") return surface::RawSampleType::Float32;
    if (n == "float64" || n == "f64") return surface::RawSampleType::Float64;
    throw InvalidArgument("raw_type '" + name +
                          "' is not recognised; valid values: float32, "
                          "float64");
}

surface::StatisticsOptions statistics_options(const std::string& level, py::handle order,
                                              py::handle cutoff_um, const std::string& acf,
                                              bool curves) {
    surface::StatisticsOptions o;
    o.leveling = surface::parse_leveling(normalize_name(level));
    if (!order.is_none()) {
        const long long n = integer_scalar("order", order);
        if (o.leveling != surface::Leveling::Polynomial)
            throw InvalidArgument(
                "order needs level='polynomial' (the order of the polynomial "
                "background, 1..3)");
        if (n < 1 || n > 3)
            throw InvalidArgument("order = " + std::to_string(n) + " is outside [1, 3]");
        o.polynomial_order = static_cast<int>(n);
    }
    o.cutoff_um = optional_real("cutoff_um", cutoff_um);
    o.acf_estimator = surface::parse_acf_estimator(normalize_name(acf));
    o.keep_curves = curves;
    return o;
}

// The statistics a prediction needs, from a dict of surface_statistics().
surface::SurfaceStatistics statistics_from_dict(py::handle stats) {
    if (!py::isinstance<py::dict>(stats))
        throw py::type_error("statistics must be a dict from surface_statistics(), not " +
                             py::str(py::type::of(stats).attr("__name__")).cast<std::string>());
    const py::dict d = py::reinterpret_borrow<py::dict>(stats);
    auto get = [&d](const char* key) -> std::optional<double> {
        if (!d.contains(key) || d[key].is_none()) return std::nullopt;
        return real_scalar(key, d[key]);
    };
    surface::SurfaceStatistics s;
    const auto sigma = get("sigma_um");
    if (!sigma) throw InvalidArgument("statistics has no sigma_um");
    s.sigma_um = *sigma;
    s.T_um = get("T_um");
    s.T_fit_gaussian_um = get("T_fit_gaussian_um");
    s.T_fit_exponential_um = get("T_fit_exponential_um");
    s.period_um = get("period_um");
    s.period_y_um = get("period_y_um");
    if (d.contains("correlation") && !d["correlation"].is_none())
        s.correlation =
            parse_correlation(normalize_name(py::str(d["correlation"]).cast<std::string>()));
    return s;
}

}  // namespace

void bind_height_files(py::module_& m) {
    using py::arg;

    m.def(
        "read_height_map",
        [](const std::string& path, std::optional<std::string> format, py::handle dx_um,
           py::handle dy_um, std::optional<std::string> unit, py::handle z_scale_um, py::handle nx,
           py::handle ny, const std::string& raw_type, bool big_endian, bool verify_checksums) {
            path_argument("path", path);
            surface::HeightReadOptions o;
            if (format) o.format = surface::parse_height_format(normalize_name(*format));
            o.dx_um = optional_real("dx_um", dx_um);
            o.dy_um = optional_real("dy_um", dy_um);
            if (o.dx_um && !o.dy_um) o.dy_um = o.dx_um;
            o.length_unit = unit;
            o.z_scale_um = optional_real("z_scale_um", z_scale_um);
            if (!nx.is_none()) {
                const long long n = integer_scalar("nx", nx);
                if (n < 1) throw InvalidArgument("nx = " + std::to_string(n) + " must be >= 1");
                o.nx = static_cast<std::size_t>(n);
            }
            if (!ny.is_none()) {
                const long long n = integer_scalar("ny", ny);
                if (n < 1) throw InvalidArgument("ny = " + std::to_string(n) + " must be >= 1");
                o.ny = static_cast<std::size_t>(n);
            }
            o.raw_type = raw_type_of(raw_type);
            o.raw_big_endian = big_endian;
            o.x3p_verify_checksums = verify_checksums;
            const surface::HeightMap map = surface::read_height_map(path, o);
            const auto f = o.format ? o.format : surface::height_format_from_extension(path);
            py::dict out = to_python(serialize::summary_json(map)).cast<py::dict>();
            out["format"] =
                f ? py::object(py::str(surface::to_string(*f))) : py::object(py::none());
            out["x_offset_um"] = map.x_offset_um;
            out["y_offset_um"] = map.y_offset_um;
            out["heights_um"] = heights_array(map);
            return out;
        },
        arg("path"), py::kw_only(), arg("format") = py::none(), arg("dx_um") = py::none(),
        arg("dy_um") = py::none(), arg("unit") = py::none(), arg("z_scale_um") = py::none(),
        arg("nx") = py::none(), arg("ny") = py::none(), arg("raw_type") = "float64",
        arg("big_endian") = false, arg("verify_checksums") = true,
        "Read a height file (csv, xyz, sdf, x3p, gwy, gsf, png, tiff, raw; format from the "
        "extension unless given). Returns a dict: heights_um (a (ny, nx) float64 array, NaN = "
        "missing), nx, ny, dx_um, dy_um, the summary keys (points, missing, min_um, ...), "
        "format, x_offset_um, y_offset_um. DataError for a malformed file, or for an x3p whose "
        "stated MD5 checksums do not match unless verify_checksums=False.");

    m.def(
        "write_height_map",
        [](py::handle heights_um, py::handle dx_um, py::handle dy_um,
           std::optional<std::string> path, std::optional<std::string> format,
           py::handle z_scale_um, bool sdf_ascii, const std::string& raw_type,
           const std::string& title) {
            if (!path) throw py::type_error("write_height_map() needs path (the file to write)");
            surface::HeightMap map = height_map_from(heights_um, dx_um, dy_um);
            map.title = title;
            surface::HeightWriteOptions o;
            if (format) o.format = surface::parse_height_format(normalize_name(*format));
            o.z_scale_um = optional_real("z_scale_um", z_scale_um);
            if (o.z_scale_um) o.tiff_float = false;
            o.sdf_binary = !sdf_ascii;
            o.raw_type = raw_type_of(raw_type);
            surface::write_height_map(map, path_argument("path", *path), o);
        },
        arg("heights_um"), arg("dx_um"), arg("dy_um") = py::none(), arg("path") = py::none(),
        py::kw_only(), arg("format") = py::none(), arg("z_scale_um") = py::none(),
        arg("sdf_ascii") = false, arg("raw_type") = "float64", arg("title") = "",
        "Write heights (a (ny, nx) array in um, NaN = missing; 1-D = a profile) with spacings "
        "dx_um, dy_um (default dx_um) to `path`, in the format of its extension unless given. "
        "Written atomically: nothing half-written on error.");
}

void bind_surface_analysis(py::module_& m) {
    using py::arg;

    m.def(
        "surface_statistics",
        [](py::handle heights_um, py::handle dx_um, py::handle dy_um, const std::string& level,
           py::handle order, py::handle cutoff_um, const std::string& acf, bool curves) {
            const surface::HeightMap map = height_map_from(heights_um, dx_um, dy_um);
            const surface::StatisticsOptions o =
                statistics_options(level, order, cutoff_um, acf, curves);
            const surface::SurfaceStatistics s = surface::surface_statistics(map, o);
            return to_python(serialize::to_json(serialize::statistics_input(map, o), s, curves));
        },
        arg("heights_um"), arg("dx_um"), arg("dy_um") = py::none(), py::kw_only(),
        arg("level") = "plane", arg("order") = py::none(), arg("cutoff_um") = py::none(),
        arg("acf") = "unbiased", arg("curves") = false,
        "Roughness statistics of heights (um; (ny, nx) or a 1-D profile) with spacings dx_um, "
        "dy_um: the dict of `roughscope surface stats --json` (file and format None), with "
        "'curves' (ACF and PSD) when curves=True. level: none, mean, line, plane, polynomial "
        "(order 1..3); cutoff_um: the Gaussian filter's cutoff; acf: unbiased or biased.");

    m.def(
        "generate_surface",
        [](const std::string& correlation, py::handle sigma_um, py::handle T_um, py::handle nx,
           py::handle ny, py::handle dx_um, py::handle dy_um, py::handle seed) {
            surface::GenerationOptions o;
            o.correlation = parse_correlation(normalize_name(correlation));
            o.sigma_um = real_scalar("sigma_um", sigma_um);
            o.T_um = real_scalar("T_um", T_um);
            const long long n_x = integer_scalar("nx", nx), n_y = integer_scalar("ny", ny);
            if (n_x < 1 || n_y < 1)
                throw InvalidArgument("nx and ny must be >= 1, got nx = " + std::to_string(n_x) +
                                      ", ny = " + std::to_string(n_y));
            o.nx = static_cast<std::size_t>(n_x);
            o.ny = static_cast<std::size_t>(n_y);
            o.dx_um = real_scalar("dx_um", dx_um);
            o.dy_um = optional_real("dy_um", dy_um).value_or(o.dx_um);
            const long long s = integer_scalar("seed", seed);
            if (s < 0) throw InvalidArgument("seed = " + std::to_string(s) + " must be >= 0");
            o.seed = static_cast<std::uint64_t>(s);
            check_allocation(static_cast<double>(n_x) * static_cast<double>(n_y), 4,
                             "a surface of " + std::to_string(n_x) + " x " + std::to_string(n_y));
            return heights_array(surface::generate_surface(o));
        },
        py::kw_only(), arg("correlation") = "gaussian", arg("sigma_um") = 1.0, arg("T_um") = 10.0,
        arg("nx") = 256, arg("ny") = 256, arg("dx_um") = 1.0, arg("dy_um") = py::none(),
        arg("seed") = 1,
        "A random surface with Gaussian heights of RMS sigma_um and Gaussian or exponential "
        "correlation of length T_um (FFT filtering of white noise; periodic; the same seed gives "
        "the same surface): a (ny, nx) float64 array in um.");

    m.def(
        "predict_brightness",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           py::handle sigma_um, py::handle T_um, std::optional<std::string> correlation,
           py::handle statistics, py::handle wavelength_um, const std::string& factor,
           const std::string& radiometry, const std::string& regime) {
            const std::vector<Geometry> geoms =
                broadcast_geometries(theta_i_deg, theta_s_deg, phi_s_deg);
            ModelOptions o;
            o.wavelength_um = real_scalar("wavelength_um", wavelength_um);
            o.factor = parse_geometric_factor(normalize_name(factor));
            o.radiometry = parse_radiometry(normalize_name(radiometry));
            o.regime = parse_regime(normalize_name(regime));
            const std::optional<Correlation> corr =
                correlation
                    ? std::optional<Correlation>(parse_correlation(normalize_name(*correlation)))
                    : std::nullopt;
            if (!statistics.is_none()) {
                if (!sigma_um.is_none() || !T_um.is_none())
                    throw InvalidArgument("give statistics or sigma_um and T_um, not both");
                const surface::SurfaceStatistics s = statistics_from_dict(statistics);
                const auto from = surface::surface_from_statistics(s, corr);
                return to_python(serialize::to_json(surface::predict_brightness(s, geoms, o, corr),
                                                    o, "statistics", from.T_source));
            }
            const std::optional<double> sigma = optional_real("sigma_um", sigma_um);
            const std::optional<double> T = optional_real("T_um", T_um);
            if (!sigma || !T)
                throw InvalidArgument(
                    "give sigma_um and T_um (um, > 0), or statistics (a dict "
                    "from surface_statistics)");
            const Surface surf{*sigma, *T, corr.value_or(Correlation::Gaussian)};
            return to_python(serialize::to_json(surface::predict_brightness(surf, geoms, o), o));
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), py::kw_only(),
        arg("sigma_um") = py::none(), arg("T_um") = py::none(), arg("correlation") = py::none(),
        arg("statistics") = py::none(), arg("wavelength_um") = 0.555, arg("factor") = "vh",
        arg("radiometry") = "radiance", arg("regime") = "auto",
        "Brightness predicted by the B-K models at the geometries (degrees; broadcast) for a "
        "surface of sigma_um, T_um and correlation (default gaussian), or for the statistics "
        "dict of surface_statistics(): the dict of `roughscope surface predict --json` (g at "
        "normal view and its roughness class, Caron's theta_K, per-geometry brightness).");
}

}  // namespace roughscope::python
