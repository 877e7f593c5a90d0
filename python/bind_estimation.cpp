// Python bindings of the §4 estimators and the least-squares fits (estimation.hpp, fit.hpp).
//
// Boundary conventions (docs/python.md, docs/estimation.md): angles in degrees (`_deg`), lengths
// in µm (`_um`). The closed forms and the two-geometry solvers are vectorised: every numeric
// argument is array-like and broadcast with NumPy's rules; all-scalar input gives a float. A bad
// element raises a roughscope.Error subclass (ValueError) whose message starts with its index.
// The estimate_* functions and the fits take scalars / 1-d arrays and return dicts built by the
// library's serializer (roughscope/serialize/estimation.hpp): the same document as the CLI's
// `roughscope estimate ... --json`, as Python objects (tests/python/test_parity.py checks it).
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/estimation.hpp"
#include "roughscope/serialize/paper_tables.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace roughscope::python {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// ---------------------------------------------------------------------------------------------
// Broadcasting: out[i] = f(x0[i], x1[i], ...), float for all-scalar input.

std::string index_text(const std::vector<py::ssize_t>& shape, py::ssize_t flat) {
    if (shape.size() == 1) return std::to_string(flat);
    std::vector<py::ssize_t> idx(shape.size());
    for (std::size_t d = shape.size(); d-- > 0;) {
        idx[d] = flat % shape[d];
        flat /= shape[d];
    }
    std::string s = "(";
    for (std::size_t d = 0; d < idx.size(); ++d) s += (d ? ", " : "") + std::to_string(idx[d]);
    return s + ")";
}

template <std::size_t N, class F>
py::object vectorize(const std::array<const char*, N>& names, const std::array<py::handle, N>& in,
                     F f) {
    std::array<DoubleArray, N> arrays;
    bool scalar = true;
    py::list as_list;
    for (std::size_t k = 0; k < N; ++k) {
        arrays[k] = DoubleArray::ensure(real_array(names[k], in[k]));  // TypeError if not real
        if (!arrays[k]) throw py::error_already_set();
        if (arrays[k].ndim() > 0) scalar = false;
        as_list.append(arrays[k]);
    }
    py::list b;
    try {
        b = py::module_::import("numpy").attr("broadcast_arrays")(*as_list);
    } catch (const py::error_already_set&) {
        std::string msg = "arguments cannot be broadcast together:";
        for (std::size_t k = 0; k < N; ++k)
            msg += std::string(k ? ", " : " ") + names[k] + " " +
                   py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                               arrays[k].shape(), arrays[k].shape() + arrays[k].ndim()))))
                       .cast<std::string>();
        throw InvalidArgument(msg);
    }
    {
        // Checked before the broadcast views are copied (and the result allocated).
        const auto view = py::reinterpret_borrow<py::array>(b[0]);
        std::vector<py::ssize_t> shape(view.shape(), view.shape() + view.ndim());
        double elements = 1.0;
        for (py::ssize_t d : shape) elements *= static_cast<double>(d);
        if (elements * 8.0 >= 1e8)
            check_allocation(elements, 1,
                             "the broadcast result of shape " +
                                 py::str(py::tuple(py::cast(shape))).cast<std::string>());
    }
    std::array<DoubleArray, N> c;
    for (std::size_t k = 0; k < N; ++k)
        c[k] = DoubleArray::ensure(py::module_::import("numpy").attr("ascontiguousarray")(b[k]));
    std::vector<py::ssize_t> shape(c[0].shape(), c[0].shape() + c[0].ndim());
    py::array_t<double> out(shape);
    double* o = out.mutable_data();
    const py::ssize_t n = out.size();
    std::array<const double*, N> data;
    for (std::size_t k = 0; k < N; ++k) data[k] = c[k].data();
    for (py::ssize_t i = 0; i < n; ++i) {
        std::array<double, N> x;
        for (std::size_t k = 0; k < N; ++k) x[k] = data[k][i];
        try {
            o[i] = std::apply(f, x);
        } catch (const NoSolution& e) {
            if (scalar) throw;
            throw NoSolution("at index " + index_text(shape, i) + ": " + e.what());
        } catch (const InvalidArgument& e) {
            if (scalar) throw;
            throw InvalidArgument("at index " + index_text(shape, i) + ": " + e.what());
        }
    }
    if (scalar) return py::float_(o[0]);
    return out;
}

double rad(double deg) { return deg_to_rad(deg); }

GeometricFactor factor_of(const std::string& s) { return parse_geometric_factor(s); }
Correlation correlation_of(const std::string& s) { return parse_correlation(s); }
Radiometry radiometry_of(const std::string& s) { return parse_radiometry(s); }

// correlation="both" → std::nullopt (both side by side), else the library's parse_correlation; the
// same rule as the CLI's --correlation (case-insensitive, listing the valid names on error).
std::optional<Correlation> correlation_or_both(const std::string& s) {
    if (name_matches("both", s)) return std::nullopt;
    try {
        return parse_correlation(s);
    } catch (const InvalidArgument&) {
        throw_unknown_name("correlation", s,
                           std::string(to_string(Correlation::Gaussian)) + ", " +
                               std::string(to_string(Correlation::Exponential)) + ", both");
    }
}

Geometry geometry_deg(double ti, double ts, double ps) {
    return make_geometry(rad(ti), rad(ts), rad(ps));
}

py::tuple range_tuple(const RatioRange& r) { return py::make_tuple(r.lower, r.upper); }

std::pair<double, double> noise_pair(py::handle noise) {
    if (noise.is_none()) return {0.0, 0.0};  // no noise given: no standard errors
    const DoubleArray a = DoubleArray::ensure(real_array("noise", noise));  // TypeError if not real
    if (!a) throw py::error_already_set();
    if (a.ndim() == 0) return {a.data()[0], a.data()[0]};
    if (a.ndim() != 1 || a.size() != 2)
        throw InvalidArgument("noise must be a number or a pair (relative noise of E1, E2)");
    return {a.data()[0], a.data()[1]};
}

// ---------------------------------------------------------------------------------------------
// Fits

std::vector<Measurement> measurements_from(py::handle theta_i_deg, py::handle theta_s_deg,
                                           py::handle phi_s_deg, py::handle brightness,
                                           py::handle weight) {
    auto as_1d = [](const char* name, py::handle h) {
        DoubleArray a = DoubleArray::ensure(real_array(name, h));  // TypeError if not real
        if (!a || a.ndim() > 1)
            throw InvalidArgument(std::string(name) +
                                  " must be a number or a 1-d array of numbers");
        return a;
    };
    DoubleArray ti = as_1d("theta_i_deg", theta_i_deg), ts = as_1d("theta_s_deg", theta_s_deg),
                ps = as_1d("phi_s_deg", phi_s_deg), b = as_1d("brightness", brightness);
    std::optional<DoubleArray> w;
    if (!weight.is_none()) w = as_1d("weight", weight);
    py::ssize_t n = b.size();
    for (auto* a : {&ti, &ts, &ps}) n = std::max(n, a->size());
    auto at = [n](const DoubleArray& a, py::ssize_t i, const char* name) {
        if (a.size() == 1) return a.data()[0];
        if (a.size() != n)
            throw InvalidArgument(std::string(name) + " has " + std::to_string(a.size()) +
                                  " values but the measurements have " + std::to_string(n));
        return a.data()[i];
    };
    std::vector<Measurement> ms;
    ms.reserve(n);
    for (py::ssize_t i = 0; i < n; ++i) {
        const double t_i = at(ti, i, "theta_i_deg"), t_s = at(ts, i, "theta_s_deg");
        const std::string where = "measurement " + std::to_string(i + 1) + " ";
        check::polar_angle(where + "theta_i", rad(t_i));
        check::polar_angle(where + "theta_s", rad(t_s));
        ms.push_back({geometry_deg(t_i, t_s, at(ps, i, "phi_s_deg")), at(b, i, "brightness"),
                      w ? at(*w, i, "weight") : 1.0});
    }
    return ms;
}

}  // namespace

void bind_paper_tables(py::module_& m) {
    m.def(
        "recompute_paper_tables",
        [](py::handle reference, const std::string& where) {
            return to_python(
                serialize::recompute_paper_tables(from_python(reference, where), where));
        },
        py::arg("reference"), py::arg("where") = "paper tables",
        "The paper's Tables 1-3 recomputed from their printed inputs (a dict with the layout of "
        "paper-tables.json) with the section-4 estimators: for each quantity {printed, "
        "recomputed, rounding_interval, agreement} with agreement 'exact', 'within_rounding' or "
        "'differs'. The document of `roughscope paper tables --json` (without 'reference').");
}

void bind_closed_form_estimators(py::module_& m) {
    using py::arg;

    // ---- §4.2 closed forms (vectorised) -----------------------------------------------------
    m.def(
        "sigma_over_T_gaussian",
        [](py::handle ratio, py::handle theta1_deg, py::handle theta2_deg,
           const std::string& factor) {
            const GeometricFactor f = factor_of(factor);
            return vectorize<3>({"ratio", "theta1_deg", "theta2_deg"},
                                {ratio, theta1_deg, theta2_deg},
                                [f](double r, double t1, double t2) {
                                    return sigma_over_T_gaussian_from_ratio(r, rad(t1), rad(t2), f);
                                });
        },
        arg("ratio"), arg("theta1_deg"), arg("theta2_deg"), arg("factor") = "vh",
        "Eq. 17: sigma/T (Gaussian correlation, very rough) from the brightness ratio E1/E2 at "
        "incidence angles theta1, theta2 (degrees), viewer on the normal. Vectorised. Raises "
        "NoSolution (a ValueError) with the valid range of ratios when there is no solution.");
    m.def(
        "sigma_over_T_exponential",
        [](py::handle ratio, py::handle theta1_deg, py::handle theta2_deg,
           const std::string& factor) {
            const GeometricFactor f = factor_of(factor);
            return vectorize<3>(
                {"ratio", "theta1_deg", "theta2_deg"}, {ratio, theta1_deg, theta2_deg},
                [f](double r, double t1, double t2) {
                    return sigma_over_T_exponential_from_ratio(r, rad(t1), rad(t2), f);
                });
        },
        arg("ratio"), arg("theta1_deg"), arg("theta2_deg"), arg("factor") = "vh",
        "Eq. 19 (exponential correlation, Eq. 5 as published): sigma/T from E1/E2 at theta1, "
        "theta2 (degrees), viewer on the normal. Vectorised.");
    m.def(
        "ratio_range_gaussian",
        [](py::handle t1_in, py::handle t2_in, const std::string& factor) {
            const double t1 = real_scalar("theta1_deg", t1_in);
            const double t2 = real_scalar("theta2_deg", t2_in);
            return range_tuple(ratio_range_gaussian(rad(t1), rad(t2), factor_of(factor)));
        },
        arg("theta1_deg"), arg("theta2_deg"), arg("factor") = "vh",
        "Open interval (lower, upper) of E1/E2 for which Eq. 17 has a solution (upper may be "
        "inf).");
    m.def(
        "ratio_range_exponential",
        [](py::handle t1_in, py::handle t2_in, const std::string& factor) {
            const double t1 = real_scalar("theta1_deg", t1_in);
            const double t2 = real_scalar("theta2_deg", t2_in);
            return range_tuple(ratio_range_exponential(rad(t1), rad(t2), factor_of(factor)));
        },
        arg("theta1_deg"), arg("theta2_deg"), arg("factor") = "vh",
        "Open interval (lower, upper) of E1/E2 for which Eq. 19 has a solution.");
    m.def(
        "ratio_range_correlation_length",
        [](py::handle sigma_um_in, py::handle t1_in, py::handle t2_in, py::handle wavelength_um_in,
           const std::string& factor) {
            const double sigma_um = real_scalar("sigma_um", sigma_um_in);
            const double t1 = real_scalar("theta1_deg", t1_in);
            const double t2 = real_scalar("theta2_deg", t2_in);
            const double wavelength_um = real_scalar("wavelength_um", wavelength_um_in);
            return range_tuple(ratio_range_correlation_length(sigma_um, rad(t1), rad(t2),
                                                              wavelength_um, factor_of(factor)));
        },
        arg("sigma_um"), arg("theta1_deg"), arg("theta2_deg"), arg("wavelength_um") = 0.555,
        arg("factor") = "vh", "Open interval of E1/E2 for which Eq. 15 has a solution.");

    // ---- §4.1 closed forms (vectorised) -----------------------------------------------------
    m.def(
        "specular_reflectance_from_brightness",
        [](py::handle E_tot, py::handle E_dif) {
            return vectorize<2>({"E_tot", "E_dif"}, {E_tot, E_dif}, [](double t, double d) {
                return specular_reflectance_from_brightness(t, d);
            });
        },
        arg("E_tot"), arg("E_dif"),
        "R_spec = 1 - E_dif/E_tot (section 4.1.1) from the peak and the surrounding diffuse "
        "brightness. Vectorised.");
    m.def(
        "sigma_from_specular",
        [](py::handle R_spec, py::handle theta_deg, py::handle wavelength_um, py::handle R0) {
            return vectorize<4>({"R_spec", "theta_deg", "wavelength_um", "R0"},
                                {R_spec, theta_deg, wavelength_um, R0},
                                [](double R, double t, double l, double r0) {
                                    return sigma_from_specular(R, rad(t), l, r0);
                                });
        },
        arg("R_spec"), arg("theta_deg"), arg("wavelength_um") = 0.555, arg("R0") = 1.0,
        "Eq. 13: RMS height sigma (um) from the specular reflectance at theta_i = theta_s = "
        "theta (degrees). R0 = 1 by default (R_spec is normalised to the peak brightness). "
        "Vectorised.");
    m.def(
        "correlation_length_from_ratio",
        [](py::handle ratio, py::handle sigma_um, py::handle theta1_deg, py::handle theta2_deg,
           py::handle wavelength_um, const std::string& factor) {
            const GeometricFactor f = factor_of(factor);
            return vectorize<5>({"ratio", "sigma_um", "theta1_deg", "theta2_deg", "wavelength_um"},
                                {ratio, sigma_um, theta1_deg, theta2_deg, wavelength_um},
                                [f](double r, double s, double t1, double t2, double l) {
                                    return correlation_length_from_ratio(r, s, rad(t1), rad(t2), l,
                                                                         f);
                                });
        },
        arg("ratio"), arg("sigma_um"), arg("theta1_deg"), arg("theta2_deg"),
        arg("wavelength_um") = 0.555, arg("factor") = "vh",
        "Eq. 15: correlation length T (um) of a slightly rough surface (Gaussian correlation) "
        "from E1/E2 at theta1, theta2 (degrees, viewer on the normal) with sigma known. "
        "Vectorised.");
}

void bind_two_geometry_solvers(py::module_& m) {
    using py::arg;

    // ---- General two-geometry solvers (vectorised) ------------------------------------------
    m.def(
        "sigma_over_T_two_geometries",
        [](py::handle ratio, py::handle ti1, py::handle ts1, py::handle ps1, py::handle ti2,
           py::handle ts2, py::handle ps2, const std::string& correlation,
           const std::string& factor, const std::string& radiometry) {
            TwoGeometryOptions o;
            o.factor = factor_of(factor);
            o.radiometry = radiometry_of(radiometry);
            const Correlation c = correlation_of(correlation);
            return vectorize<7>(
                {"ratio", "theta_i1_deg", "theta_s1_deg", "phi_s1_deg", "theta_i2_deg",
                 "theta_s2_deg", "phi_s2_deg"},
                {ratio, ti1, ts1, ps1, ti2, ts2, ps2},
                [o, c](double r, double a1, double b1, double c1, double a2, double b2, double c2) {
                    return sigma_over_T_two_geometries(r, geometry_deg(a1, b1, c1),
                                                       geometry_deg(a2, b2, c2), c, o);
                });
        },
        arg("ratio"), arg("theta_i1_deg"), arg("theta_s1_deg"), arg("phi_s1_deg"),
        arg("theta_i2_deg"), arg("theta_s2_deg"), arg("phi_s2_deg"),
        arg("correlation") = "gaussian", arg("factor") = "vh", arg("radiometry") = "radiance",
        "sigma/T of a very rough surface (Eq. 4 or Eq. 5) from E1/E2 measured at two arbitrary "
        "geometries (degrees; phi_s = 0 is the specular plane), by bracketed root finding "
        "(TOMS 748). Equals sigma_over_T_gaussian/_exponential at normal view. Vectorised.");
    m.def(
        "correlation_length_two_geometries",
        [](py::handle ratio, py::handle sigma_um, py::handle ti1, py::handle ts1, py::handle ps1,
           py::handle ti2, py::handle ts2, py::handle ps2, const std::string& correlation,
           const std::string& factor, const std::string& radiometry, const std::string& regime,
           py::handle wavelength_um_in) {
            const double wavelength_um = real_scalar("wavelength_um", wavelength_um_in);
            TwoGeometryOptions o;
            o.factor = factor_of(factor);
            o.radiometry = radiometry_of(radiometry);
            o.regime = parse_regime(regime);
            o.wavelength_um = wavelength_um;
            const Correlation c = correlation_of(correlation);
            return vectorize<8>({"ratio", "sigma_um", "theta_i1_deg", "theta_s1_deg", "phi_s1_deg",
                                 "theta_i2_deg", "theta_s2_deg", "phi_s2_deg"},
                                {ratio, sigma_um, ti1, ts1, ps1, ti2, ts2, ps2},
                                [o, c](double r, double s, double a1, double b1, double c1,
                                       double a2, double b2, double c2) {
                                    return correlation_length_two_geometries(
                                        r, geometry_deg(a1, b1, c1), geometry_deg(a2, b2, c2), s, c,
                                        o);
                                });
        },
        arg("ratio"), arg("sigma_um"), arg("theta_i1_deg"), arg("theta_s1_deg"), arg("phi_s1_deg"),
        arg("theta_i2_deg"), arg("theta_s2_deg"), arg("phi_s2_deg"),
        arg("correlation") = "gaussian", arg("factor") = "vh", arg("radiometry") = "radiance",
        arg("regime") = "slightly_rough", arg("wavelength_um") = 0.555,
        "Correlation length T (um) with sigma known from E1/E2 at two arbitrary geometries, from "
        "the diffuse term in the chosen regime (slightly_rough = Eq. 3; series/auto = exact "
        "series; both correlations). TOMS 748 root finding. Vectorised.");
}

void bind_estimates(py::module_& m) {
    using py::arg;

    // ---- Estimates with uncertainty and derived quantities (scalar, dict) -------------------
    // Standard errors (`*_stderr` keys) are reported when a noise level (or sigma_um_stderr) is
    // given, as with the CLI's --noise / --sigma-stderr.
    m.def(
        "estimate_slope",
        [](py::handle ratio_in, py::handle theta1_deg_in, py::handle theta2_deg_in,
           const std::string& correlation, const std::string& factor, const std::string& radiometry,
           py::handle noise, py::handle sigma_um_in, py::handle wavelength_um_in,
           py::handle theta_s1_deg_in, py::handle phi_s1_deg_in, py::handle theta_s2_deg_in,
           py::handle phi_s2_deg_in) {
            const double ratio = real_scalar("ratio", ratio_in);
            const double theta1_deg = real_scalar("theta1_deg", theta1_deg_in);
            const double theta2_deg = real_scalar("theta2_deg", theta2_deg_in);
            const std::optional<double> sigma_um = optional_real("sigma_um", sigma_um_in);
            const double wavelength_um = real_scalar("wavelength_um", wavelength_um_in);
            const double theta_s1_deg = real_scalar("theta_s1_deg", theta_s1_deg_in);
            const double phi_s1_deg = real_scalar("phi_s1_deg", phi_s1_deg_in);
            const double theta_s2_deg = real_scalar("theta_s2_deg", theta_s2_deg_in);
            const double phi_s2_deg = real_scalar("phi_s2_deg", phi_s2_deg_in);
            SlopeInput in;
            in.E1_over_E2 = ratio;
            in.geom1 = geometry_deg(theta1_deg, theta_s1_deg, phi_s1_deg);
            in.geom2 = geometry_deg(theta2_deg, theta_s2_deg, phi_s2_deg);
            in.options.factor = factor_of(factor);
            in.options.radiometry = radiometry_of(radiometry);
            in.options.wavelength_um = wavelength_um;
            const auto [n1, n2] = noise_pair(noise);
            in.noise = {n1, n2};
            in.sigma_um = sigma_um;
            const std::optional<Correlation> c = correlation_or_both(correlation);  // none: both
            std::optional<RoughnessEstimate> eg, ee;
            if (c != Correlation::Exponential) {
                in.correlation = Correlation::Gaussian;
                eg = estimate_slope(in);
            }
            if (c != Correlation::Gaussian) {
                in.correlation = Correlation::Exponential;
                ee = estimate_slope(in);
            }
            return to_python(serialize::slope_estimate_json(in, eg, ee, !noise.is_none()));
        },
        arg("ratio"), arg("theta1_deg"), arg("theta2_deg"), arg("correlation") = "gaussian",
        arg("factor") = "vh", arg("radiometry") = "radiance", arg("noise") = py::none(),
        arg("sigma_um") = py::none(), arg("wavelength_um") = 0.555, arg("theta_s1_deg") = 0.0,
        arg("phi_s1_deg") = 0.0, arg("theta_s2_deg") = 0.0, arg("phi_s2_deg") = 0.0,
        "sigma/T (Eq. 17/19, or the two-geometry solver when theta_s != 0) for correlation "
        "'gaussian', 'exponential' or 'both', with standard errors (*_stderr) when the relative "
        "brightness noise is given (a number or a pair), and the derived quantities: "
        "theta_K_deg, xi_K, rms_slope, roughness_class, g (when sigma_um is known), warnings. "
        "Returns the dict of `roughscope estimate slope --json` (docs/estimation.md).");
    m.def(
        "estimate_sigma_specular",
        [](py::handle R_spec_in, py::handle theta_deg_in, py::handle E_tot_in, py::handle E_dif_in,
           py::handle wavelength_um_in, py::handle R0_in, py::handle noise_in) {
            const std::optional<double> R_spec = optional_real("R_spec", R_spec_in);
            const double theta_deg = real_scalar("theta_deg", theta_deg_in);
            const std::optional<double> E_tot = optional_real("E_tot", E_tot_in);
            const std::optional<double> E_dif = optional_real("E_dif", E_dif_in);
            const double wavelength_um = real_scalar("wavelength_um", wavelength_um_in);
            const double R0 = real_scalar("R0", R0_in);
            const std::optional<double> noise = optional_real("noise", noise_in);
            SpecularInput in;
            if (R_spec && (E_tot || E_dif))
                throw InvalidArgument("give R_spec or (E_tot, E_dif), not both");
            if (!R_spec && !(E_tot && E_dif))
                throw InvalidArgument("give R_spec, or both E_tot and E_dif");
            if (R_spec) in.R_spec = *R_spec;
            in.E_tot = E_tot;
            in.E_dif = E_dif;
            in.theta_rad = rad(theta_deg);
            in.wavelength_um = wavelength_um;
            in.R0 = R0;
            in.relative_noise_tot = in.relative_noise_dif = noise.value_or(0.0);
            return to_python(serialize::specular_estimate_json(in, estimate_sigma_specular(in),
                                                               noise.has_value()));
        },
        arg("R_spec") = py::none(), arg("theta_deg") = 0.0, arg("E_tot") = py::none(),
        arg("E_dif") = py::none(), arg("wavelength_um") = 0.555, arg("R0") = 1.0,
        arg("noise") = py::none(),
        "sigma (Eq. 13), with its standard error when the relative noise of E_tot and E_dif is "
        "given, g at the specular geometry and the roughness class. Returns the dict of "
        "`roughscope estimate specular --json`.");
    m.def(
        "estimate_correlation_length",
        [](py::handle ratio_in, py::handle sigma_um_in, py::handle theta1_deg_in,
           py::handle theta2_deg_in, py::handle sigma_um_stderr_in, const std::string& correlation,
           const std::string& factor, const std::string& radiometry, const std::string& regime,
           py::handle wavelength_um_in, py::handle noise, py::handle theta_s1_deg_in,
           py::handle phi_s1_deg_in, py::handle theta_s2_deg_in, py::handle phi_s2_deg_in) {
            const double ratio = real_scalar("ratio", ratio_in);
            const double sigma_um = real_scalar("sigma_um", sigma_um_in);
            const double theta1_deg = real_scalar("theta1_deg", theta1_deg_in);
            const double theta2_deg = real_scalar("theta2_deg", theta2_deg_in);
            const std::optional<double> sigma_um_stderr =
                optional_real("sigma_um_stderr", sigma_um_stderr_in);
            const double wavelength_um = real_scalar("wavelength_um", wavelength_um_in);
            const double theta_s1_deg = real_scalar("theta_s1_deg", theta_s1_deg_in);
            const double phi_s1_deg = real_scalar("phi_s1_deg", phi_s1_deg_in);
            const double theta_s2_deg = real_scalar("theta_s2_deg", theta_s2_deg_in);
            const double phi_s2_deg = real_scalar("phi_s2_deg", phi_s2_deg_in);
            CorrelationLengthInput in;
            in.E1_over_E2 = ratio;
            in.sigma_um = sigma_um;
            in.sigma_um_std_error = sigma_um_stderr.value_or(0.0);
            in.geom1 = geometry_deg(theta1_deg, theta_s1_deg, phi_s1_deg);
            in.geom2 = geometry_deg(theta2_deg, theta_s2_deg, phi_s2_deg);
            in.correlation = correlation_of(correlation);
            in.options.factor = factor_of(factor);
            in.options.radiometry = radiometry_of(radiometry);
            in.options.regime = parse_regime(regime);
            in.options.wavelength_um = wavelength_um;
            const auto [n1, n2] = noise_pair(noise);
            in.noise = {n1, n2};
            return to_python(serialize::correlation_length_estimate_json(
                in, estimate_correlation_length(in),
                !noise.is_none() || sigma_um_stderr.has_value()));
        },
        arg("ratio"), arg("sigma_um"), arg("theta1_deg"), arg("theta2_deg"),
        arg("sigma_um_stderr") = py::none(), arg("correlation") = "gaussian", arg("factor") = "vh",
        arg("radiometry") = "radiance", arg("regime") = "slightly_rough",
        arg("wavelength_um") = 0.555, arg("noise") = py::none(), arg("theta_s1_deg") = 0.0,
        arg("phi_s1_deg") = 0.0, arg("theta_s2_deg") = 0.0, arg("phi_s2_deg") = 0.0,
        "T (Eq. 15, or the two-geometry solver) with sigma known, with standard errors when the "
        "brightness noise or sigma_um_stderr is given; sigma/T, theta_K, xi_K, g, class, "
        "warnings. Returns the dict of `roughscope estimate correlation-length --json`.");
}

void bind_fits(py::module_& m) {
    using py::arg;

    // ---- Least-squares fits -----------------------------------------------------------------
    // The options become a FitOptions in one place: serialize::fit_options_from (the CLI calls
    // it too).
    auto fit_doc =
        "Least-squares fit (Ceres) of sigma/T (model='very_rough') or sigma and T "
        "(model='slightly_rough') and the gain K to N brightness values at geometries "
        "theta_i_deg, theta_s_deg, phi_s_deg (1-d arrays; phi_s = 0 is the specular plane). "
        "Returns the dict of `roughscope estimate fit --correlation C --json [--residuals]`: "
        "status, message, sigma_over_T(_stderr), gain(_stderr), parameters (their number), "
        "parameter_table (name, value, stderr, lower, upper, at_bound), covariance (natural "
        "units, None when unavailable), residuals and predicted (residuals=True), sse, aic, aicc, "
        "n, iterations, report, theta_K_deg, xi_K, rms_slope, roughness_class, g, warnings.";
    auto fit_fn = [](py::handle ti, py::handle ts, py::handle ps, py::handle brightness,
                     py::handle weight, const py::dict& options, bool residuals,
                     bool compare) -> py::object {
        const auto ms = measurements_from(ti, ts, ps, brightness, weight);
        const FitOptions o = serialize::fit_options_from(from_python(options, "fit option"));
        if (!compare) {
            FitResult r;
            {
                py::gil_scoped_release release;
                r = fit_roughness(ms, o);
            }
            return to_python(serialize::fit_estimate_json(o, ms.size(), r, residuals));
        }
        CorrelationComparison c;
        {
            py::gil_scoped_release release;
            c = compare_correlations(ms, o);
        }
        return to_python(serialize::fit_estimate_json(o, ms.size(), c, residuals));
    };
    m.def(
        "fit_roughness",
        [fit_fn](py::handle ti, py::handle ts, py::handle ps, py::handle b, py::handle w,
                 py::object model, py::object correlation, py::object factor, py::object radiometry,
                 py::object regime, py::object wavelength_um, py::object residual, py::object loss,
                 py::object loss_scale, py::object i_s, py::object i_sigma, py::object i_T,
                 py::object sb, py::object sigb, py::object tb, py::object max_iterations,
                 py::object scale_covariance, bool residuals) {
            const py::dict o(
                "model"_a = model, "correlation"_a = correlation, "factor"_a = factor,
                "radiometry"_a = radiometry, "regime"_a = regime,
                "wavelength_um"_a = real_option("wavelength_um", wavelength_um, false, false),
                "residual"_a = residual, "loss"_a = loss,
                "loss_scale"_a = real_option("loss_scale", loss_scale, false, false),
                "initial_sigma_over_T"_a = real_option("initial_sigma_over_T", i_s),
                "initial_sigma_um"_a = real_option("initial_sigma_um", i_sigma),
                "initial_T_um"_a = real_option("initial_T_um", i_T),
                "sigma_over_T_bounds"_a = real_option("sigma_over_T_bounds", sb, true),
                "sigma_bounds_um"_a = real_option("sigma_bounds_um", sigb, true),
                "T_bounds_um"_a = real_option("T_bounds_um", tb, true),
                "max_iterations"_a = py::int_(integer_scalar("max_iterations", max_iterations)),
                "scale_covariance"_a = scale_covariance);
            return fit_fn(ti, ts, ps, b, w, o, residuals, false);
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("brightness"),
        arg("weight") = py::none(), arg("model") = "very_rough", arg("correlation") = "gaussian",
        arg("factor") = "vh", arg("radiometry") = "radiance", arg("regime") = "slightly_rough",
        arg("wavelength_um") = 0.555, arg("residual") = "relative", arg("loss") = "none",
        arg("loss_scale") = 0.05, arg("initial_sigma_over_T") = py::none(),
        arg("initial_sigma_um") = py::none(), arg("initial_T_um") = py::none(),
        arg("sigma_over_T_bounds") = py::none(), arg("sigma_bounds_um") = py::none(),
        arg("T_bounds_um") = py::none(), arg("max_iterations") = 200,
        arg("scale_covariance") = true, arg("residuals") = true, fit_doc);
    m.def(
        "compare_correlations",
        [fit_fn](py::handle ti, py::handle ts, py::handle ps, py::handle b, py::handle w,
                 py::object model, py::object factor, py::object radiometry, py::object regime,
                 py::object wavelength_um, py::object residual, py::object loss,
                 py::object loss_scale, bool residuals) {
            const py::dict o(
                "model"_a = model, "factor"_a = factor, "radiometry"_a = radiometry,
                "regime"_a = regime,
                "wavelength_um"_a = real_option("wavelength_um", wavelength_um, false, false),
                "residual"_a = residual, "loss"_a = loss,
                "loss_scale"_a = real_option("loss_scale", loss_scale, false, false));
            return fit_fn(ti, ts, ps, b, w, o, residuals, true);
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("brightness"),
        arg("weight") = py::none(), arg("model") = "very_rough", arg("factor") = "vh",
        arg("radiometry") = "radiance", arg("regime") = "slightly_rough",
        arg("wavelength_um") = 0.555, arg("residual") = "relative", arg("loss") = "none",
        arg("loss_scale") = 0.05, arg("residuals") = true,
        "Fits both correlation functions (see fit_roughness) and compares them by AIC. Returns "
        "the dict of `roughscope estimate fit --correlation both --json`: "
        "preferred_correlation, delta_aic = AIC(other) - AIC(preferred), the preferred fit's "
        "sigma_over_T, sigma_over_T_gaussian/_exponential, and each fit under 'gaussian' and "
        "'exponential'.");
}

}  // namespace roughscope::python
