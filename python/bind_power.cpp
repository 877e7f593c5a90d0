// Python bindings of the B–K mean scattered power (Eq. 1–5), the very-rough brightness from σ/T
// alone, the series sums and the diffuse terms as pure functions. Array arguments broadcast as
// array_loops.hpp describes.
#include <cstdint>
#include <span>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "array_loops.hpp"
#include "bindings.hpp"
#include "roughscope/roughscope.hpp"
#include "roughscope/scattering/brightness_batch.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

// mean_scattered_power over arrays: a dict of the terms, the regime and class used and the
// method, each a float (str) for all-scalar input, else an array of the broadcast shape.
py::dict mean_scattered_power_py(py::handle theta_i_deg, py::handle theta_s_deg,
                                 py::handle phi_s_deg, py::handle sigma_um, py::handle T_um,
                                 const std::string& correlation, const std::string& factor,
                                 const std::string& regime, const std::string& radiometry,
                                 py::handle wavelength_um, py::handle patch_x_um,
                                 py::handle patch_y_um, py::handle auto_tolerance_in) {
    const double auto_tolerance = real_scalar("auto_tolerance", auto_tolerance_in);
    const Correlation corr = parse_correlation(correlation);
    ModelOptions opt;
    opt.factor = parse_geometric_factor(factor);
    opt.regime = parse_regime(regime);
    opt.radiometry = parse_radiometry(radiometry);
    opt.auto_tolerance = auto_tolerance;
    auto operands = broadcast<8>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "sigma_um", "T_um",
                                  "wavelength_um", "patch_x_um", "patch_y_um"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg, sigma_um, T_um,
                                  wavelength_um, patch_x_um, patch_y_um});
    auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
    auto& b = operands.second;
    py::array_t<double> coh = make_output(b), dif = make_output(b), tot = make_output(b),
                        bri = make_output(b), gg = make_output(b), bnd = make_output(b);
    py::array_t<std::uint8_t> reg(b.shape), cls(b.shape), met(b.shape);
    double *oc = coh.mutable_data(), *od = dif.mutable_data(), *ot = tot.mutable_data(),
           *ob = bri.mutable_data(), *og = gg.mutable_data(), *obd = bnd.mutable_data();
    std::uint8_t *orr = reg.mutable_data(), *ocl = cls.mutable_data(), *om = met.mutable_data();
    for_each_element(b, true, [&](ssize_t i) {
        const auto x = values_at(ops, i);
        ModelOptions o = opt;
        o.wavelength_um = x[5];
        o.patch_x_um = x[6];
        o.patch_y_um = x[7];
        const ScatteredPower p =
            mean_scattered_power(geometry_deg(x[0], x[1], x[2]), Surface{x[3], x[4], corr}, o);
        oc[i] = p.coherent;
        od[i] = p.diffuse;
        ot[i] = p.total;
        ob[i] = p.brightness;
        og[i] = p.g;
        obd[i] = p.relative_error_bound;
        om[i] = code_of(kMethods, p.method);
        orr[i] = code_of(kRegimes, p.regime);
        ocl[i] = code_of(kRoughnessClasses, p.roughness_class);
    });
    py::dict d;
    d["coherent"] = finish(b, coh);
    d["diffuse"] = finish(b, dif);
    d["total"] = finish(b, tot);
    d["brightness"] = finish(b, bri);
    d["g"] = finish(b, gg);
    d["regime"] = names_from_codes(b, reg, enum_names(kRegimes));
    d["roughness_class"] = names_from_codes(b, cls, enum_names(kRoughnessClasses));
    d["method"] = names_from_codes(b, met, enum_names(kMethods));
    d["relative_error_bound"] = finish(b, bnd);
    return d;
}

// =============================================================================================
// very_rough_brightness over arrays: the library's batch kernel (scattering/brightness_batch.hpp)
// =============================================================================================

py::object very_rough_brightness_py(py::handle theta_i_deg, py::handle theta_s_deg,
                                    py::handle phi_s_deg, py::handle sigma_over_T,
                                    const std::string& correlation, const std::string& factor,
                                    const std::string& radiometry) {
    const BrightnessBatchModel model{parse_correlation(correlation), parse_geometric_factor(factor),
                                     parse_radiometry(radiometry)};
    auto operands = broadcast<4>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "sigma_over_T"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg, sigma_over_T});
    auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
    auto& b = operands.second;
    if (b.scalar) {  // one value: the library's own function
        const double x = very_rough_brightness(
            geometry_deg(ops[0].data[0], ops[1].data[0], ops[2].data[0]), ops[3].data[0],
            model.correlation, model.factor, model.radiometry);
        return py::float_(x);
    }
    const auto n = static_cast<std::size_t>(b.size);
    auto span_of = [n](const Operand& op) {
        return std::span<const double>(op.data, op.step == 0 ? 1 : n);
    };
    const BrightnessBatchInput in{span_of(ops[0]), span_of(ops[1]), span_of(ops[2]),
                                  span_of(ops[3]), AngleUnit::Degrees};
    py::array_t<double> out = make_output(b);
    const std::span<double> o(out.mutable_data(), n);
    run_chunks(b, worker_count(b.size, 16384), [&](ssize_t begin, ssize_t end, ssize_t& at) {
        std::size_t bad = static_cast<std::size_t>(begin);
        try {
            very_rough_brightness_batch(in, o, model, static_cast<std::size_t>(begin),
                                        static_cast<std::size_t>(end), bad);
        } catch (...) {
            at = static_cast<ssize_t>(bad);
            throw;
        }
    });
    return finish(b, out);
}

}  // namespace

void bind_mean_scattered_power(py::module_& m) {
    using py::arg;

    m.def("mean_scattered_power", &mean_scattered_power_py, arg("theta_i_deg"), arg("theta_s_deg"),
          arg("phi_s_deg"), arg("sigma_um"), arg("T_um"), py::kw_only(),
          arg("correlation") = "gaussian", arg("factor") = "vh", arg("regime") = "auto",
          arg("radiometry") = "radiance", arg("wavelength_um") = 0.555, arg("patch_x_um") = 500.0,
          arg("patch_y_um") = 500.0, arg("auto_tolerance") = 1e-12,
          R"doc(Beckmann–Kirchhoff mean scattered power, Eq. 1: P = ρ0² exp(−g) + D.

D for correlation='gaussian': Eq. 2 (regime 'series'), Eq. 3 ('slightly_rough'), Eq. 4
('very_rough' = 'very_rough_series_limit'); for 'exponential': the exact series ('series'),
its first term ('slightly_rough'), Eq. 5 as published ('very_rough') or the g → ∞ limit of the
exact series ('very_rough_series_limit'). 'auto' uses the series unless the first term alone
is accurate to auto_tolerance.

Angles in degrees (θ in [0, 90)); sigma_um, T_um, wavelength_um, patch_x_um, patch_y_um in µm,
> 0 (the illuminated patch is 2X × 2Y, A = 4XY). factor: 'vh' (default), 'beckmann', 'ogilvy',
'kirchhoff'; radiometry: 'radiance' (default, brightness = P) or 'intensity' (P / cos θs).
All numeric arguments broadcast together.

Returns a dict: 'coherent', 'diffuse', 'total' (= P), 'brightness', 'g' (floats or arrays),
'regime' (the regime actually used, never 'auto'), 'roughness_class' ('slightly_rough',
'moderately_rough', 'very_rough' by g) and 'method' ('closed_form', 'summation' or
'large_g_expansion': how D was evaluated; the series switches to its large-g expansion where the
sum underflows or loses accuracy): a str for scalar input, else a NumPy str array of the
broadcast shape; 'relative_error_bound' (float or array): bound on the relative error of D against
the exact series (0 for a closed form asked for by name). Lengths must be in [1e-30, 1e30] µm.)doc");

    m.def("very_rough_brightness", &very_rough_brightness_py, arg("theta_i_deg"),
          arg("theta_s_deg"), arg("phi_s_deg"), arg("sigma_over_T"), py::kw_only(),
          arg("correlation") = "gaussian", arg("factor") = "vh", arg("radiometry") = "radiance",
          R"doc(Very-rough diffuse brightness from σ/T alone (constants dropped), §4.2 and §5:
  gaussian (Eq. 4):    F²/q_z² exp(−q_xy² / (4 (σ/T)² q_z²))
  exponential (Eq. 5): F² / (q_z² [1 + q_xy² / ((σ/T)² q_z²)]^{3/2})
with q = v/k, times 1/cos θs for radiometry='intensity'. factor as in geometric_factor_squared.

Angles in degrees (θ in [0, 90), φs finite), sigma_over_T > 0; all four broadcast together.
Scalars go through the library's scalar function; arrays through a compiled parallel loop
(vector math, agrees with the scalar function to ~1e-14 relative). Every element is validated
before any is computed; the first bad one is reported with its index.)doc");
}

void bind_diffuse_terms(py::module_& m) {
    using py::arg;

    // ---- Series sums and diffuse terms (Eq. 2–5) ------------------------------------------
    m.def(
        "gaussian_series_sum",
        [](py::handle g, py::handle T2_vxy2) {
            return map_double<2>({"g", "T2_vxy2"}, {g, T2_vxy2}, [](double gg, double a) {
                check::non_negative("g", gg);
                check::non_negative("T2_vxy2", a);
                return gaussian_series_sum(gg, a);
            });
        },
        arg("g"), arg("T2_vxy2"),
        R"doc(S_G(g, T²v_xy²) = exp(−g) Σ_{n≥1} gⁿ/(n! n) exp(−T² v_xy² / (4n)): the sum of Eq. 2
without its prefactor. g >= 0, T2_vxy2 = T² v_xy² >= 0 (dimensionless).)doc");

    m.def(
        "exponential_series_sum",
        [](py::handle g, py::handle T2_vxy2) {
            return map_double<2>({"g", "T2_vxy2"}, {g, T2_vxy2}, [](double gg, double bb) {
                check::non_negative("g", gg);
                check::non_negative("T2_vxy2", bb);
                return exponential_series_sum(gg, bb);
            });
        },
        arg("g"), arg("T2_vxy2"),
        R"doc(S_E(g, T²v_xy²) = exp(−g) Σ_{n≥1} gⁿ/n! · n/(n² + T² v_xy²)^{3/2}: the exact
exponential-correlation series without its prefactor. g >= 0, T2_vxy2 >= 0.)doc");

    // Diffuse terms as pure functions of F², lengths (µm), area A (µm²), g and v (1/µm).
    auto series_like = [&m](const char* name, auto fn, const char* doc) {
        m.def(
            name,
            [fn](py::handle F2, py::handle T_um, py::handle area_um2, py::handle g,
                 py::handle vxy2) {
                return map_double<5>({"F2", "T_um", "area_um2", "g", "vxy2"},
                                     {F2, T_um, area_um2, g, vxy2},
                                     [fn](double f2, double T, double A, double gg, double v) {
                                         check::non_negative("F2", f2);
                                         check::positive("T_um", T, "um");
                                         check::positive("area_um2", A, "um^2");
                                         check::non_negative("g", gg);
                                         check::non_negative("vxy2", v, "1/um^2");
                                         return representable(fn(f2, T, A, gg, v));
                                     });
            },
            py::arg("F2"), py::arg("T_um"), py::arg("area_um2"), py::arg("g"), py::arg("vxy2"),
            doc);
    };
    series_like(
        "diffuse_power_gaussian_series",
        [](double a, double b, double c, double d, double e) {
            return diffuse_power_gaussian_series(a, b, c, d, e);
        },
        "Eq. 2: (πT²/A) F² exp(−g) Σ gⁿ/(n! n) exp(−T² v_xy²/(4n)). vxy2 = v_xy² in 1/µm².");
    series_like(
        "diffuse_power_slightly_rough_gaussian",
        [](double a, double b, double c, double d, double e) {
            return diffuse_power_slightly_rough_gaussian(a, b, c, d, e);
        },
        "Eq. 3: (πT²/A) g F² exp(−g − T² v_xy²/4). vxy2 in 1/µm².");
    series_like(
        "diffuse_power_exponential_series",
        [](double a, double b, double c, double d, double e) {
            return diffuse_power_exponential_series(a, b, c, d, e);
        },
        "Exact exponential-correlation series: (2πT²/A) F² exp(−g) Σ gⁿ/n! · n/(n² + "
        "T² v_xy²)^{3/2}.");
    series_like(
        "diffuse_power_slightly_rough_exponential",
        [](double a, double b, double c, double d, double e) {
            return diffuse_power_slightly_rough_exponential(a, b, c, d, e);
        },
        "First term of the exact exponential series: (2πT²/A) F² g exp(−g) / (1 + "
        "T² v_xy²)^{3/2}.");
    series_like(
        "diffuse_power_very_rough_exponential_series_limit",
        [](double a, double b, double c, double d, double e) {
            return diffuse_power_very_rough_exponential_series_limit(a, b, c, d, e);
        },
        "g → ∞ limit of the exact exponential series: (2πT²/A) F² g / (g² + T² "
        "v_xy²)^{3/2}.");

    auto very_rough_like = [&m](const char* name, auto fn, const char* doc) {
        m.def(
            name,
            [fn](py::handle F2, py::handle sigma_um, py::handle T_um, py::handle area_um2,
                 py::handle vz2, py::handle vxy2) {
                return map_double<6>(
                    {"F2", "sigma_um", "T_um", "area_um2", "vz2", "vxy2"},
                    {F2, sigma_um, T_um, area_um2, vz2, vxy2},
                    [fn](double f2, double s, double T, double A, double vz, double v) {
                        check::non_negative("F2", f2);
                        check::positive("sigma_um", s, "um");
                        check::positive("T_um", T, "um");
                        check::positive("area_um2", A, "um^2");
                        check::positive("vz2", vz, "1/um^2");
                        check::non_negative("vxy2", v, "1/um^2");
                        return representable(fn(f2, s, T, A, vz, v));
                    });
            },
            py::arg("F2"), py::arg("sigma_um"), py::arg("T_um"), py::arg("area_um2"),
            py::arg("vz2"), py::arg("vxy2"), doc);
    };
    very_rough_like(
        "diffuse_power_very_rough_gaussian",
        [](double a, double b, double c, double d, double e, double f) {
            return diffuse_power_very_rough_gaussian(a, b, c, d, e, f);
        },
        "Eq. 4: (πT²/(Aσ²)) F²/v_z² exp(−T² v_xy² / (4σ² v_z²)). vz2, vxy2 in 1/µm².");
    very_rough_like(
        "diffuse_power_very_rough_exponential",
        [](double a, double b, double c, double d, double e, double f) {
            return diffuse_power_very_rough_exponential(a, b, c, d, e, f);
        },
        "Eq. 5 as published: (2πT²/(Aσ²)) F² / (v_z² [1 + T² v_xy²/(σ² "
        "v_z²)]^{3/2}).");

    m.def(
        "diffuse_power_quadrature",
        [](const std::string& correlation, py::handle F2, py::handle T_um, py::handle area_um2,
           py::handle g, py::handle vxy2) {
            const Correlation c = parse_correlation(correlation);
            return map_double<5>(
                {"F2", "T_um", "area_um2", "g", "vxy2"}, {F2, T_um, area_um2, g, vxy2},
                [c](double f2, double T, double A, double gg, double v) {
                    return diffuse_power_quadrature(c, f2, T, A, gg, v);
                },
                /*parallel=*/false);
        },
        arg("correlation"), arg("F2"), arg("T_um"), arg("area_um2"), arg("g"), arg("vxy2"),
        R"doc(The diffuse Kirchhoff integral by direct numerical quadrature, independent of the series:
D = (2π/A) F² exp(−g) ∫₀^∞ [exp(g C(τ)) − 1] J0(v_xy τ) τ dτ, C the 'gaussian' or 'exponential'
correlation. Slow (up to ~0.3 s per value). Domain: 0 <= g <= 1e4 and 0 <= T v_xy <= 100 (else
InvalidArgument naming the value); absolute error <= 1e-12 of the integral's size at the lobe
centre; never negative.)doc");
}

}  // namespace roughscope::python
