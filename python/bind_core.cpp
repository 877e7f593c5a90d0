// Python bindings of the named choices, the reference-data locator, the imaging geometry (§2)
// and the scattering vector, g and geometric factors (§3.1–3.2). Array arguments broadcast as
// array_loops.hpp describes.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "array_loops.hpp"
#include "bindings.hpp"
#include "roughscope/io/data_locator.hpp"
#include "roughscope/roughscope.hpp"
#include "roughscope/scattering/brightness_batch.hpp"

namespace py = pybind11;

namespace roughscope::python {

void bind_names_and_shared_data(py::module_& m) {
    using py::arg;

    m.attr("CORRELATIONS") = py::tuple(py::cast(enum_names(kCorrelations)));
    m.attr("FACTORS") = py::tuple(py::cast(enum_names(kFactors)));
    m.attr("RADIOMETRIES") = py::tuple(py::cast(enum_names(kRadiometries)));
    m.attr("REGIMES") = py::tuple(py::cast(enum_names(kRegimes)));
    m.attr("ROUGHNESS_CLASSES") = py::tuple(py::cast(enum_names(kRoughnessClasses)));
    m.attr("SLIGHTLY_ROUGH_MAX_G") = kSlightlyRoughMaxG;
    m.attr("VERY_ROUGH_MIN_G") = kVeryRoughMinG;

    // ---- Reference data beside the project (io/data_locator.hpp) ----------------------------
    using Starts = std::vector<std::filesystem::path>;
    m.def(
        "shared_dir_candidates",
        [](const Starts& extra_starts) { return io::shared_dir_candidates(extra_starts); },
        arg("extra_starts") = Starts{},
        "The shared folders searched, in order: $ROUGHSCOPE_SHARED_DIR alone when set, else "
        "../shared from the current directory upward, then from each of extra_starts.");
    m.def(
        "find_shared",
        [](const std::string& relative, const Starts& extra_starts) {
            return io::find_shared(relative, extra_starts);
        },
        arg("relative"), arg("extra_starts") = Starts{},
        "Path of `relative` in the first shared folder holding it, or None.");
    m.def(
        "paper_tables_path",
        [](const Starts& extra_starts) { return io::paper_tables_path(extra_starts); },
        arg("extra_starts") = Starts{},
        "Path of reference/paper-tables.json in the shared folder, or None.");
    m.def(
        "curet_data_dir",
        [](const Starts& extra_starts) { return io::curet_data_dir(extra_starts); },
        arg("extra_starts") = Starts{},
        "The shared folder's data/curet (holding table.txt and abrdf.dat), or None.");
    m.def(
        "shared_search_description",
        [](const std::string& relative) { return io::shared_search_description(relative); },
        arg("relative"), "One line saying where `relative` is looked for.");
    m.def("shared_data_required", &io::shared_data_required,
          "True when ROUGHSCOPE_REQUIRE_SHARED_DATA=1: tests must fail, not skip, when the "
          "shared data are missing.");
    // ---- Private knobs for tests and benchmarks ---------------------------------------------
    m.def(
        "_set_vector_isa",
        [](const std::string& name) {
            return std::string(to_string(set_vector_isa_cap(parse_vector_isa(name))));
        },
        arg("isa"),
        "Testing aid: cap the instruction set of the array kernels ('generic', 'avx2', "
        "'avx512' or 'best'); returns the one now in use (never above what the CPU has).");
    m.def(
        "_set_max_threads",
        [](int n) {
            if (n < 0)
                throw InvalidArgument("max_threads = " + std::to_string(n) + " must be >= 0");
            set_max_worker_threads(n);
        },
        arg("n"), "Benchmark aid: cap the worker threads of array loops (0: no cap).");
}

void bind_geometry(py::module_& m) {
    using py::arg;

    // ---- Geometry (§2) --------------------------------------------------------------------
    m.def(
        "geometry_from_vectors",
        [](py::handle N, py::handle L, py::handle V, py::handle unit_tolerance_in) {
            const double unit_tolerance = real_scalar("unit_tolerance", unit_tolerance_in);
            auto operands = broadcast<3>({"N", "L", "V"}, {N, L, V}, 3);
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> ti = make_output(b), ts = make_output(b), ps = make_output(b);
            py::array_t<bool> visible(b.shape);
            double *oi = ti.mutable_data(), *os = ts.mutable_data(), *op = ps.mutable_data();
            bool* ov = visible.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                auto vec = [&](int k) {
                    const double* p = ops[k].data + i * ops[k].step;
                    return Eigen::Vector3d(p[0], p[1], p[2]);
                };
                const std::optional<Geometry> g =
                    geometry_from_vectors(vec(0), vec(1), vec(2), unit_tolerance);
                ov[i] = g.has_value();
                oi[i] = g ? rad_to_deg(g->theta_i_rad) : 0.0;
                os[i] = g ? rad_to_deg(g->theta_s_rad) : 0.0;
                op[i] = g ? rad_to_deg(g->phi_s_rad) : 0.0;
            });
            if (b.scalar) return py::make_tuple(oi[0], os[0], op[0], py::bool_(ov[0]));
            return py::make_tuple(ti, ts, ps, visible);
        },
        arg("N"), arg("L"), arg("V"), arg("unit_tolerance") = 1e-6,
        R"doc(Imaging geometry from the surface normal N, light direction L and viewing direction V
(paper §2, Fig. 2): θi = acos(N·L), θs = acos(N·V), φs = π − angle between the
tangent-plane projections of L and V (so φs = 0 is the specular plane, 180 retro).

N, L, V: unit vectors, array-likes of shape (..., 3), broadcast over the leading dimensions;
they must be finite and of unit length within unit_tolerance (else roughscope.InvalidArgument).
L and V point away from the surface.

Returns (theta_i_deg, theta_s_deg, phi_s_deg, visible). phi_s_deg is in [0, 180]. Where L or
V is at or below the horizon (N·L <= 0 or N·V <= 0) visible is False and the three angles
are 0 (brightness there is a physical zero, not an error). Floats and a bool for single
vectors, arrays of the leading shape otherwise.)doc");

    m.def(
        "geometry_from_two_azimuths",
        [](py::handle theta_i_deg, py::handle phi_i_deg, py::handle theta_v_deg,
           py::handle phi_v_deg) {
            auto operands = broadcast<4>({"theta_i_deg", "phi_i_deg", "theta_v_deg", "phi_v_deg"},
                                         {theta_i_deg, phi_i_deg, theta_v_deg, phi_v_deg});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> ti = make_output(b), ts = make_output(b), ps = make_output(b);
            double *oi = ti.mutable_data(), *os = ts.mutable_data(), *op = ps.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const auto x = values_at(ops, i);
                const Geometry g = geometry_from_two_azimuths(deg_to_rad(x[0]), deg_to_rad(x[1]),
                                                              deg_to_rad(x[2]), deg_to_rad(x[3]));
                oi[i] = rad_to_deg(g.theta_i_rad);
                os[i] = rad_to_deg(g.theta_s_rad);
                op[i] = rad_to_deg(g.phi_s_rad);
            });
            return py::make_tuple(finish(b, ti), finish(b, ts), finish(b, ps));
        },
        arg("theta_i_deg"), arg("phi_i_deg"), arg("theta_v_deg"), arg("phi_v_deg"),
        R"doc(Geometry in the paper's frame (§2) from a frame that gives both azimuths (e.g.
CUReT's θv, φv, θi, φi): θs = θv, φs = φv − φi + 180 (mod 360).

All angles in degrees; polar angles in [0, 90). Returns (theta_i_deg, theta_s_deg,
phi_s_deg) with phi_s_deg in [0, 360).)doc");
}

void bind_scattering_vector(py::module_& m) {
    using py::arg;

    // ---- Scattering vector, g, F (§3.1–3.2) -------------------------------------------------
    m.def(
        "scattering_vector",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           py::handle wavelength_um) {
            auto operands =
                broadcast<4>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "wavelength_um"},
                             {theta_i_deg, theta_s_deg, phi_s_deg, wavelength_um});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> vx = make_output(b), vy = make_output(b), vz = make_output(b);
            double *ox = vx.mutable_data(), *oy = vy.mutable_data(), *oz = vz.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const auto x = values_at(ops, i);
                const Geometry g = geometry_deg(x[0], x[1], x[2]);
                check_length_um("wavelength_um", x[3]);
                const ScatteringVector v = scattering_vector(g, x[3]);
                ox[i] = v.vx;
                oy[i] = v.vy;
                oz[i] = v.vz;
            });
            return py::make_tuple(finish(b, vx), finish(b, vy), finish(b, vz));
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("wavelength_um") = 0.555,
        R"doc(Scattering vector v = (vx, vy, vz) in 1/µm (§3.1):
vx = k (sin θi − sin θs cos φs), vy = −k sin θs sin φs, vz = −k (cos θi + cos θs),
k = 2π/λ. Angles in degrees, wavelength_um > 0 (default 0.555, the paper's). Returns (vx, vy, vz).)doc");

    m.def(
        "roughness_g",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle sigma_um,
           py::handle wavelength_um) {
            return map_double<4>({"theta_i_deg", "theta_s_deg", "sigma_um", "wavelength_um"},
                                 {theta_i_deg, theta_s_deg, sigma_um, wavelength_um},
                                 [](double ti, double ts, double sigma, double wl) {
                                     const Geometry g = geometry_deg(ti, ts, 0.0);
                                     check::non_negative("sigma_um", sigma, "um");
                                     if (sigma != 0.0) check_length_um("sigma_um", sigma);
                                     check_length_um("wavelength_um", wl);
                                     return roughness_g(g, sigma, wl);
                                 });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("sigma_um"), arg("wavelength_um") = 0.555,
        R"doc(Roughness parameter g = σ² v_z² = (2πσ/λ)² (cos θi + cos θs)² (§3.1); it does not
depend on φs. sigma_um >= 0, wavelength_um > 0 (µm), angles in degrees, in [0, 90).)doc");

    m.def(
        "geometric_factor_squared",
        [](const std::string& factor, py::handle theta_i_deg, py::handle theta_s_deg,
           py::handle phi_s_deg) {
            const GeometricFactor f = parse_geometric_factor(factor);
            return map_double<3>({"theta_i_deg", "theta_s_deg", "phi_s_deg"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg},
                                 [f](double ti, double ts, double ps) {
                                     return geometric_factor_squared(f, geometry_deg(ti, ts, ps));
                                 });
        },
        arg("factor"), arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"),
        R"doc(Squared geometric factor F² of the diffuse term (§3.2):
'beckmann' F_Beck (Eq. 6), 'vh' F_VH² = cos θi (Vernold–Harvey), 'ogilvy' F_Beck cos θi,
'kirchhoff' F_Beck cos θi / cos θs. Angles in degrees.)doc");

    m.def(
        "geometric_factor_beckmann",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg) {
            return map_double<3>({"theta_i_deg", "theta_s_deg", "phi_s_deg"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg},
                                 [](double ti, double ts, double ps) {
                                     return geometric_factor_beckmann(geometry_deg(ti, ts, ps));
                                 });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"),
        R"doc(Beckmann's geometric factor, Eq. 6:
F_Beck = (1 + cos θi cos θs − sin θi sin θs cos φs) / (cos θi (cos θi + cos θs)).
F_Beck(0, 0, ·) = 1; retro (θ, θ, 180): 1/cos²θ. Angles in degrees.)doc");

    m.def(
        "specular_amplitude_rho0",
        [](py::handle vx, py::handle vy, py::handle patch_x_um, py::handle patch_y_um) {
            return map_double<4>({"vx", "vy", "patch_x_um", "patch_y_um"},
                                 {vx, vy, patch_x_um, patch_y_um},
                                 [](double x, double y, double X, double Y) {
                                     check::finite("vx", x);
                                     check::finite("vy", y);
                                     check_length_um("patch_x_um", X);
                                     check_length_um("patch_y_um", Y);
                                     return specular_amplitude_rho0(x, y, X, Y);
                                 });
        },
        arg("vx"), arg("vy"), arg("patch_x_um") = 500.0, arg("patch_y_um") = 500.0,
        R"doc(ρ0 = sinc(vx X) sinc(vy Y) for a 2X × 2Y patch (§3.1); vx, vy in 1/µm, X, Y in µm.
ρ0 = 1 in the specular direction (vx = vy = 0).)doc");

    m.def(
        "coherent_power",
        [](py::handle rho0, py::handle g) {
            return map_double<2>({"rho0", "g"}, {rho0, g}, [](double r, double gg) {
                if (!(r >= -1.0 && r <= 1.0))  // ρ0 is a product of two sincs (§3.1)
                    throw InvalidArgument("rho0 = " + check::format_number(r) +
                                          " is outside the valid range [-1, 1]");
                check::non_negative("g", gg);
                return coherent_power(r, gg);
            });
        },
        arg("rho0"), arg("g"), "Coherent term of Eq. 1: ρ0² exp(−g).");
}

}  // namespace roughscope::python
