// Python bindings of the simulation topic (simulation/kirchhoff.hpp): the Kirchhoff Monte Carlo,
// vectorised over geometries, and the scattering integral of one height map.
//
// simulate_scatter returns the serializer's document (serialize/simulation.hpp), the same as
// `roughscope simulate scatter --json`; its options are keyword arguments checked like every
// numeric argument of the module (TypeError naming a non-real value). The run releases the GIL;
// Ctrl-C (KeyboardInterrupt) and the optional progress callback are served between realisations,
// and an exception from either stops the run.
#include <complex>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/simulation.hpp"
#include "roughscope/simulation/kirchhoff.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A count argument: None → `absent`, else a non-negative integer (TypeError for a non-integer).
std::size_t non_negative_count(const char* name, py::handle value, std::size_t absent) {
    if (value.is_none()) return absent;
    const long long v = integer_scalar(name, value);
    if (v < 0) throw InvalidArgument(concat(name, " = ", std::to_string(v), " must be >= 0"));
    return static_cast<std::size_t>(v);
}

// A seed: an integer in [0, 2^64 − 1] (TypeError for a non-integer, InvalidArgument outside).
// (integer_scalar's long long would refuse the upper half of the range.)
std::uint64_t seed_from(py::handle value) {
    const py::module_ np = py::module_::import("numpy");
    // (NumPy's timedelta64 derives from its signedinteger: not an integer here.)
    const bool integer =
        !PyBool_Check(value.ptr()) &&
        (PyLong_Check(value.ptr()) || (py::isinstance(value, np.attr("integer")) &&
                                       !py::isinstance(value, np.attr("timedelta64"))));
    if (!integer) {
        throw py::type_error(concat(
            "seed must be an integer (int or a NumPy integer), not ",
            value.is_none() ? std::string("None")
                            : py::str(py::type::of(value).attr("__name__")).cast<std::string>()));
    }
    const py::int_ v(py::reinterpret_borrow<py::object>(value));
    const unsigned long long s = PyLong_AsUnsignedLongLong(v.ptr());
    if (PyErr_Occurred() != nullptr) {
        PyErr_Clear();
        throw InvalidArgument(concat("seed = ", int_text(v),
                                     " is out of range: it must be an integer in [0, 2^64 - 1]"));
    }
    return static_cast<std::uint64_t>(s);
}

// The options of simulate_scatter and check_simulate_scatter (the same keyword arguments),
// validated by check_scatter_options.
simulation::ScatterOptions scatter_options(py::handle sigma_um, py::handle T_um,
                                           const std::string& correlation, py::handle wavelength_um,
                                           const std::string& factor, py::handle n,
                                           py::handle dx_um, py::handle patch_over_T,
                                           py::handle realisations, py::handle seed,
                                           const std::string& layout, py::handle threads,
                                           const py::object& progress) {
    if (!progress.is_none() && PyCallable_Check(progress.ptr()) == 0)
        throw py::type_error("progress must be a callable (done, total) or None");
    simulation::ScatterOptions o;
    o.correlation = parse_correlation(normalize_name(correlation));
    o.sigma_um = real_scalar("sigma_um", sigma_um);
    o.T_um = real_scalar("T_um", T_um);
    o.wavelength_um = real_scalar("wavelength_um", wavelength_um);
    o.factor = parse_geometric_factor(normalize_name(factor));
    o.n = non_negative_count("n", n, 0);
    o.dx_um = optional_real("dx_um", dx_um).value_or(0.0);
    o.patch_over_T = optional_real("patch_over_T", patch_over_T).value_or(0.0);
    const long long r = integer_scalar("realisations", realisations);
    if (r < 10 || r > 10'000'000)
        throw InvalidArgument(concat("realisations = ", std::to_string(r),
                                     " is out of range: it must be in [10, 1e7] (fewer give no "
                                     "usable standard error)"));
    o.realisations = static_cast<std::size_t>(r);
    o.seed = seed_from(seed);
    o.layout = simulation::parse_patch_layout(normalize_name(layout));
    const long long t = integer_scalar("threads", threads);
    if (t < 0 || t > 1024)
        throw InvalidArgument(concat("threads = ", std::to_string(t),
                                     " is out of range: it must be in [0, 1024] (0 = all "
                                     "cores)"));
    o.threads = static_cast<unsigned>(t);
    simulation::check_scatter_options(o);
    return o;
}

}  // namespace

void bind_simulation(py::module_& m) {
    using py::arg;
    m.def(
        "simulate_scatter",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           py::handle sigma_um, py::handle T_um, const std::string& correlation,
           py::handle wavelength_um, const std::string& factor, py::handle n, py::handle dx_um,
           py::handle patch_over_T, py::handle realisations, py::handle seed,
           const std::string& layout, py::handle threads, const py::object& progress) {
            const simulation::ScatterOptions o =
                scatter_options(sigma_um, T_um, correlation, wavelength_um, factor, n, dx_um,
                                patch_over_T, realisations, seed, layout, threads, progress);
            const std::vector<Geometry> geoms =
                broadcast_geometries(theta_i_deg, theta_s_deg, phi_s_deg);
            if (geoms.empty())
                throw InvalidArgument("no geometry given: the angle arrays are empty");
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
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), py::kw_only(), arg("sigma_um"),
        arg("T_um"), arg("correlation") = "gaussian", arg("wavelength_um") = 0.555,
        arg("factor") = "beckmann", arg("n") = py::none(), arg("dx_um") = py::none(),
        arg("patch_over_T") = py::none(), arg("realisations") = 100, arg("seed") = 1,
        arg("layout") = "lattice_aligned", arg("threads") = 0, arg("progress") = py::none(),
        "Monte Carlo Kirchhoff scattering on generated surfaces at the geometries (degrees; "
        "broadcast): the dict of `roughscope simulate scatter --json` ('options', 'results' with "
        "diffuse, diffuse_stderr, coherent, coherent_stderr, series_diffuse, g, ... per geometry). "
        "n and dx_um (None = chosen from the geometry), patch_over_T (None = chosen), threads "
        "(0 = all cores), progress (a callable(done, total) or None). docs/simulation.md.");

    m.def(
        "check_simulate_scatter",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           py::handle sigma_um, py::handle T_um, const std::string& correlation,
           py::handle wavelength_um, const std::string& factor, py::handle n, py::handle dx_um,
           py::handle patch_over_T, py::handle realisations, py::handle seed,
           const std::string& layout, py::handle threads, const py::object& progress) {
            const simulation::ScatterOptions o =
                scatter_options(sigma_um, T_um, correlation, wavelength_um, factor, n, dx_um,
                                patch_over_T, realisations, seed, layout, threads, progress);
            const std::vector<Geometry> geoms =
                broadcast_geometries(theta_i_deg, theta_s_deg, phi_s_deg);
            if (geoms.empty())
                throw InvalidArgument("no geometry given: the angle arrays are empty");
            py::list plans;
            for (const simulation::ScatterPlanSummary& plan :
                 simulation::check_scattering_run(geoms, o)) {
                py::dict d;
                d["n"] = plan.n;
                d["dx_um"] = plan.dx_um;
                d["generated_n"] = plan.generated_n;
                d["layout"] = std::string(simulation::to_string(plan.layout));
                d["lattice_index"] = plan.lattice_index;
                plans.append(d);
            }
            return plans;
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), py::kw_only(), arg("sigma_um"),
        arg("T_um"), arg("correlation") = "gaussian", arg("wavelength_um") = 0.555,
        arg("factor") = "beckmann", arg("n") = py::none(), arg("dx_um") = py::none(),
        arg("patch_over_T") = py::none(), arg("realisations") = 100, arg("seed") = 1,
        arg("layout") = "lattice_aligned", arg("threads") = 0, arg("progress") = py::none(),
        "Validates a simulate_scatter call without running it: the same arguments, the same "
        "InvalidArgument/TypeError that simulate_scatter would raise before its first realisation "
        "(options, geometries, the grid chosen or given at each geometry). Returns one dict per "
        "geometry (broadcast, C order) with the grid the run will use: 'n', 'dx_um', 'layout', "
        "'lattice_index' (as in its results) and 'generated_n' (the side of the surface "
        "generated per realisation). Cheap: no surface is generated. "
        "docs/simulation-sweeps.md.");

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
