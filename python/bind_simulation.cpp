// Python bindings of the simulation topic (simulation/kirchhoff.hpp): the Kirchhoff Monte Carlo,
// vectorised over geometries, and the scattering integral of one height map.
//
// simulate_scatter returns the serializer's document (serialize/simulation.hpp), the same as
// `roughscope simulate scatter --json`. The run releases the GIL; Ctrl-C (KeyboardInterrupt) and
// the optional progress callback are served between realisations, and an exception from either
// stops the run.
#include <complex>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/simulation.hpp"
#include "roughscope/simulation/kirchhoff.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<Geometry> broadcast_geometries(py::handle theta_i_deg, py::handle theta_s_deg,
                                           py::handle phi_s_deg) {
    const py::object np = py::module_::import("numpy");
    py::list arrays;
    arrays.append(real_array("theta_i_deg", theta_i_deg));
    arrays.append(real_array("theta_s_deg", theta_s_deg));
    arrays.append(real_array("phi_s_deg", phi_s_deg));
    py::list b;
    try {
        b = np.attr("broadcast_arrays")(*arrays);
    } catch (const py::error_already_set&) {
        throw InvalidArgument(
            "theta_i_deg, theta_s_deg and phi_s_deg cannot be broadcast together");
    }
    const auto ti = DoubleArray::ensure(np.attr("ravel")(b[0]));
    const auto ts = DoubleArray::ensure(np.attr("ravel")(b[1]));
    const auto ps = DoubleArray::ensure(np.attr("ravel")(b[2]));
    std::vector<Geometry> geoms;
    for (py::ssize_t i = 0; i < ti.size(); ++i)
        geoms.push_back(make_geometry(deg_to_rad(ti.data()[i]), deg_to_rad(ts.data()[i]),
                                      deg_to_rad(ps.data()[i])));
    if (geoms.empty()) throw InvalidArgument("no geometry given: the angle arrays are empty");
    return geoms;
}

}  // namespace

void bind_simulation(py::module_& m) {
    using py::arg;
    m.def(
        "simulate_scatter",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           const py::kwargs& kwargs) {
            py::object progress = py::none();
            py::dict options;
            for (const auto& [key, value] : kwargs) {
                if (py::str(key).cast<std::string>() == "progress") {
                    progress = py::reinterpret_borrow<py::object>(value);
                } else {
                    options[key] = value;
                }
            }
            if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
                throw py::type_error("progress must be a callable (done, total) or None");
            const std::vector<Geometry> geoms =
                broadcast_geometries(theta_i_deg, theta_s_deg, phi_s_deg);
            const simulation::ScatterOptions o =
                serialize::scatter_options_from(from_python(options, "simulate_scatter option"));
            std::vector<simulation::ScatterResult> results;
            {
                py::gil_scoped_release release;
                results = simulation::simulate_scattering(
                    geoms, o, [&progress](std::size_t done, std::size_t total) {
                        py::gil_scoped_acquire acquire;
                        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                        if (!progress.is_none()) progress(done, total);
                    });
            }
            return to_python(serialize::to_json(results, o));
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"),
        "Monte Carlo Kirchhoff scattering on generated surfaces at the geometries (degrees; "
        "broadcast): the dict of `roughscope simulate scatter --json` ('options', 'results' with "
        "diffuse, diffuse_stderr, coherent, coherent_stderr, series_diffuse, g, ... per geometry). "
        "Keyword options: correlation ('gaussian'), sigma_um, T_um, wavelength_um (0.555), factor "
        "('beckmann'), n and dx_um (None = chosen), patch_over_T (None = chosen), realisations "
        "(100), seed (1), layout ('lattice_aligned' or 'fixed'), threads (0 = all cores), "
        "progress (a callable(done, total) or None). docs/simulation.md.");

    m.def(
        "scattering_integral_lattice",
        [](py::handle heights_um, py::handle dx_um, py::handle vz_per_um, py::handle dy_um) {
            const surface::HeightMap map = height_map_from(heights_um, dx_um, dy_um);
            const double vz = real_scalar("vz_per_um", vz_per_um);
            check_allocation(static_cast<double>(map.size()), 6, "the scattering lattice");
            simulation::LatticeField field;
            {
                py::gil_scoped_release release;
                field = simulation::scattering_integral_lattice(map, vz);
            }
            py::array_t<std::complex<double>> out(
                {static_cast<py::ssize_t>(field.ny), static_cast<py::ssize_t>(field.nx)});
            std::memcpy(out.mutable_data(), field.values.data(),
                        field.values.size() * sizeof(std::complex<double>));
            py::dict d;
            d["values"] = out;
            d["dvx_per_um"] = field.dvx_per_um;
            d["dvy_per_um"] = field.dvy_per_um;
            d["vz_per_um"] = field.vz_per_um;
            return d;
        },
        arg("heights_um"), arg("dx_um"), arg("vz_per_um"), py::kw_only(), arg("dy_um") = py::none(),
        "The scattering integral I = rho/F of one height map (um, (ny, nx)) for one v_z on the "
        "whole lattice v_xy = 2 pi (i/Lx, j/Ly): a dict with 'values' (complex (ny, nx), FFT "
        "order: numpy.fft.fftfreq indexing), 'dvx_per_um', 'dvy_per_um', 'vz_per_um'.");

    m.def(
        "scattering_integral_at",
        [](py::handle heights_um, py::handle dx_um, py::handle vx, py::handle vy, py::handle vz,
           py::handle dy_um) {
            const surface::HeightMap map = height_map_from(heights_um, dx_um, dy_um);
            const ScatteringVector v{real_scalar("vx_per_um", vx), real_scalar("vy_per_um", vy),
                                     real_scalar("vz_per_um", vz)};
            return simulation::scattering_integral_at(map, v);
        },
        arg("heights_um"), arg("dx_um"), arg("vx_per_um"), arg("vy_per_um"), arg("vz_per_um"),
        py::kw_only(), arg("dy_um") = py::none(),
        "The scattering integral I = rho/F of one height map at one scattering vector v (1/um) "
        "by direct summation (coordinates centred on the map): a complex number.");
}

}  // namespace roughscope::python
