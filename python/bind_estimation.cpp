// Python bindings of the §4 estimators and the least-squares fits (estimation.hpp, fit.hpp).
//
// Boundary conventions (docs/python.md, docs/estimation.md): angles in degrees (`_deg`), lengths
// in µm (`_um`). The closed forms and the two-geometry solvers are vectorised: every numeric
// argument is array-like and broadcast with NumPy's rules; all-scalar input gives a float. A bad
// element raises a roughscope.Error subclass (ValueError) whose message starts with its index.
// The estimate_* functions and the fits take scalars / 1-d arrays and return dicts whose keys are
// those of the CLI's --json output.
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
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

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
        arrays[k] = DoubleArray::ensure(in[k]);
        if (!arrays[k])
            throw InvalidArgument(std::string(names[k]) +
                                  " must be a real number or an array-like of real numbers");
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

Geometry geometry_deg(double ti, double ts, double ps) {
    return make_geometry(rad(ti), rad(ts), rad(ps));
}

py::tuple range_tuple(const RatioRange& r) { return py::make_tuple(r.lower, r.upper); }

// ---------------------------------------------------------------------------------------------
// RoughnessEstimate → dict with the CLI's JSON keys.

void put(py::dict& d, const std::string& key, const std::optional<Estimate>& e,
         double scale = 1.0) {
    if (e) {
        d[key.c_str()] = e->value * scale;
        d[(key + "_stderr").c_str()] = e->std_error * scale;
    } else {
        d[key.c_str()] = py::none();
        d[(key + "_stderr").c_str()] = py::none();
    }
}

py::dict estimate_dict(const RoughnessEstimate& e) {
    py::dict d;
    put(d, "sigma_um", e.sigma_um);
    put(d, "T_um", e.T_um);
    put(d, "sigma_over_T", e.sigma_over_T);
    d["correlation"] = std::string(to_string(e.correlation));
    put(d, "theta_K_deg", e.theta_K_rad, 180.0 / kPi);
    put(d, "xi_K", e.xi_K);
    put(d, "rms_slope", e.rms_slope);
    d["roughness_class"] = std::string(to_string(e.roughness_class));
    d["roughness_class_assumed"] = e.roughness_class_assumed;
    if (e.g.empty())
        d["g"] = py::none();
    else
        d["g"] = py::array_t<double>(static_cast<py::ssize_t>(e.g.size()), e.g.data());
    d["warnings"] = e.warnings;
    return d;
}

std::pair<double, double> noise_pair(py::handle noise) {
    if (noise.is_none()) return {0.0, 0.0};
    if (py::isinstance<py::sequence>(noise) && !py::isinstance<py::str>(noise)) {
        auto v = noise.cast<std::vector<double>>();
        if (v.size() != 2)
            throw InvalidArgument("noise must be a number or a pair (relative noise of E1, E2)");
        return {v[0], v[1]};
    }
    const double x = noise.cast<double>();
    return {x, x};
}

// ---------------------------------------------------------------------------------------------
// Fits

std::vector<Measurement> measurements_from(py::handle theta_i_deg, py::handle theta_s_deg,
                                           py::handle phi_s_deg, py::handle brightness,
                                           py::handle weight) {
    auto as_1d = [](const char* name, py::handle h) {
        DoubleArray a = DoubleArray::ensure(h);
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

FitOptions fit_options_from(const std::string& model, const std::string& correlation,
                            const std::string& factor, const std::string& radiometry,
                            const std::string& regime, double wavelength_um,
                            const std::string& residual, const std::string& loss, double loss_scale,
                            std::optional<double> initial_sigma_over_T,
                            std::optional<double> initial_sigma_um,
                            std::optional<double> initial_T_um, py::handle sigma_over_T_bounds,
                            py::handle sigma_bounds_um, py::handle T_bounds_um, int max_iterations,
                            bool scale_covariance) {
    FitOptions o;
    o.model = parse_fit_model(model);
    o.correlation = correlation_of(correlation);
    o.factor = factor_of(factor);
    o.radiometry = radiometry_of(radiometry);
    o.regime = parse_regime(regime);
    o.wavelength_um = wavelength_um;
    o.residual = parse_residual_type(residual);
    o.loss = parse_loss_type(loss);
    o.loss_scale = loss_scale;
    o.initial_sigma_over_T = initial_sigma_over_T;
    o.initial_sigma_um = initial_sigma_um;
    o.initial_T_um = initial_T_um;
    auto bounds = [](const char* name, py::handle h, double& lo, double& hi) {
        if (h.is_none()) return;
        auto v = h.cast<std::vector<double>>();
        if (v.size() != 2)
            throw InvalidArgument(std::string(name) + " must be a pair (lower, upper)");
        lo = v[0];
        hi = v[1];
    };
    bounds("sigma_over_T_bounds", sigma_over_T_bounds, o.sigma_over_T_min, o.sigma_over_T_max);
    bounds("sigma_bounds_um", sigma_bounds_um, o.sigma_min_um, o.sigma_max_um);
    bounds("T_bounds_um", T_bounds_um, o.T_min_um, o.T_max_um);
    o.max_iterations = max_iterations;
    o.scale_covariance = scale_covariance;
    return o;
}

py::dict fit_dict(const FitResult& r) {
    py::dict d = estimate_dict(r.estimate);
    d["status"] = std::string(to_string(r.status));
    d["message"] = r.message;
    py::dict params;
    for (const auto& p : r.parameters) {
        params[p.name.c_str()] =
            py::dict("value"_a = p.value,
                     "stderr"_a = r.covariance_available ? py::object(py::float_(p.std_error))
                                                         : py::object(py::none()),
                     "lower"_a = p.lower, "upper"_a = p.upper, "at_bound"_a = p.at_bound);
    }
    d["parameters"] = params;
    const FitParameter& gain = r.parameter("gain");
    d["gain"] = gain.value;
    d["gain_stderr"] =
        r.covariance_available ? py::object(py::float_(gain.std_error)) : py::object(py::none());
    if (!r.covariance_available) {
        for (const char* k : {"sigma_um_stderr", "T_um_stderr", "sigma_over_T_stderr",
                              "theta_K_deg_stderr", "xi_K_stderr", "rms_slope_stderr"})
            if (d.contains(k)) d[k] = py::none();
    }
    d["covariance_available"] = r.covariance_available;
    d["covariance"] =
        r.covariance_available ? py::object(py::cast(r.covariance)) : py::object(py::none());
    d["residuals"] =
        py::array_t<double>(static_cast<py::ssize_t>(r.residuals.size()), r.residuals.data());
    d["predicted"] =
        py::array_t<double>(static_cast<py::ssize_t>(r.predicted.size()), r.predicted.data());
    d["sse"] = r.sse;
    d["aic"] = r.aic;
    d["aicc"] = r.aicc;
    d["n"] = r.num_measurements;
    d["num_parameters"] = r.num_parameters;
    d["iterations"] = r.iterations;
    d["model"] = std::string(to_string(r.options.model));
    d["report"] = r.brief_report();
    return d;
}

}  // namespace

void bind_estimation(py::module_& m) {
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
        [](double t1, double t2, const std::string& factor) {
            return range_tuple(ratio_range_gaussian(rad(t1), rad(t2), factor_of(factor)));
        },
        arg("theta1_deg"), arg("theta2_deg"), arg("factor") = "vh",
        "Open interval (lower, upper) of E1/E2 for which Eq. 17 has a solution (upper may be "
        "inf).");
    m.def(
        "ratio_range_exponential",
        [](double t1, double t2, const std::string& factor) {
            return range_tuple(ratio_range_exponential(rad(t1), rad(t2), factor_of(factor)));
        },
        arg("theta1_deg"), arg("theta2_deg"), arg("factor") = "vh",
        "Open interval (lower, upper) of E1/E2 for which Eq. 19 has a solution.");
    m.def(
        "ratio_range_correlation_length",
        [](double sigma_um, double t1, double t2, double wavelength_um, const std::string& factor) {
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
           double wavelength_um) {
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

    // ---- Estimates with uncertainty and derived quantities (scalar, dict) -------------------
    m.def(
        "estimate_slope",
        [](double ratio, double theta1_deg, double theta2_deg, const std::string& correlation,
           const std::string& factor, const std::string& radiometry, py::handle noise,
           std::optional<double> sigma_um, double wavelength_um, double theta_s1_deg,
           double phi_s1_deg, double theta_s2_deg, double phi_s2_deg) {
            SlopeInput in;
            in.E1_over_E2 = ratio;
            in.geom1 = geometry_deg(theta1_deg, theta_s1_deg, phi_s1_deg);
            in.geom2 = geometry_deg(theta2_deg, theta_s2_deg, phi_s2_deg);
            in.correlation = correlation_of(correlation);
            in.options.factor = factor_of(factor);
            in.options.radiometry = radiometry_of(radiometry);
            in.options.wavelength_um = wavelength_um;
            const auto [n1, n2] = noise_pair(noise);
            in.noise = {n1, n2};
            in.sigma_um = sigma_um;
            return estimate_dict(estimate_slope(in));
        },
        arg("ratio"), arg("theta1_deg"), arg("theta2_deg"), arg("correlation") = "gaussian",
        arg("factor") = "vh", arg("radiometry") = "radiance", arg("noise") = 0.0,
        arg("sigma_um") = py::none(), arg("wavelength_um") = 0.555, arg("theta_s1_deg") = 0.0,
        arg("phi_s1_deg") = 0.0, arg("theta_s2_deg") = 0.0, arg("phi_s2_deg") = 0.0,
        "sigma/T (Eq. 17/19, or the two-geometry solver when theta_s != 0) with its standard "
        "error from the relative brightness noise (a number or a pair), and the derived "
        "quantities: theta_K_deg, xi_K, rms_slope, roughness_class, g (when sigma_um is known), "
        "warnings. Returns a dict with the keys of `roughscope estimate slope --json`.");
    m.def(
        "estimate_sigma_specular",
        [](std::optional<double> R_spec, double theta_deg, std::optional<double> E_tot,
           std::optional<double> E_dif, double wavelength_um, double R0, double noise) {
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
            in.relative_noise_tot = in.relative_noise_dif = noise;
            return estimate_dict(estimate_sigma_specular(in));
        },
        arg("R_spec") = py::none(), arg("theta_deg") = 0.0, arg("E_tot") = py::none(),
        arg("E_dif") = py::none(), arg("wavelength_um") = 0.555, arg("R0") = 1.0,
        arg("noise") = 0.0,
        "sigma (Eq. 13) with its standard error from the relative noise of E_tot and E_dif, g at "
        "the specular geometry and the roughness class. Returns a dict.");
    m.def(
        "estimate_correlation_length",
        [](double ratio, double sigma_um, double theta1_deg, double theta2_deg,
           double sigma_um_stderr, const std::string& correlation, const std::string& factor,
           const std::string& radiometry, const std::string& regime, double wavelength_um,
           py::handle noise, double theta_s1_deg, double phi_s1_deg, double theta_s2_deg,
           double phi_s2_deg) {
            CorrelationLengthInput in;
            in.E1_over_E2 = ratio;
            in.sigma_um = sigma_um;
            in.sigma_um_std_error = sigma_um_stderr;
            in.geom1 = geometry_deg(theta1_deg, theta_s1_deg, phi_s1_deg);
            in.geom2 = geometry_deg(theta2_deg, theta_s2_deg, phi_s2_deg);
            in.correlation = correlation_of(correlation);
            in.options.factor = factor_of(factor);
            in.options.radiometry = radiometry_of(radiometry);
            in.options.regime = parse_regime(regime);
            in.options.wavelength_um = wavelength_um;
            const auto [n1, n2] = noise_pair(noise);
            in.noise = {n1, n2};
            return estimate_dict(estimate_correlation_length(in));
        },
        arg("ratio"), arg("sigma_um"), arg("theta1_deg"), arg("theta2_deg"),
        arg("sigma_um_stderr") = 0.0, arg("correlation") = "gaussian", arg("factor") = "vh",
        arg("radiometry") = "radiance", arg("regime") = "slightly_rough",
        arg("wavelength_um") = 0.555, arg("noise") = 0.0, arg("theta_s1_deg") = 0.0,
        arg("phi_s1_deg") = 0.0, arg("theta_s2_deg") = 0.0, arg("phi_s2_deg") = 0.0,
        "T (Eq. 15, or the two-geometry solver) with sigma known, with standard errors from the "
        "brightness noise and sigma_um_stderr; sigma/T, theta_K, xi_K, g, class, warnings.");

    // ---- Least-squares fits -----------------------------------------------------------------
    auto fit_doc =
        "Least-squares fit (Ceres) of sigma/T (model='very_rough') or sigma and T "
        "(model='slightly_rough') and the gain K to N brightness values at geometries "
        "theta_i_deg, theta_s_deg, phi_s_deg (1-d arrays; phi_s = 0 is the specular plane). "
        "Returns a dict: status, message, parameters (value, stderr, bounds, at_bound), "
        "sigma_over_T(_stderr), gain, covariance (natural units), residuals, predicted, sse, aic, "
        "aicc, n, iterations, report, theta_K_deg, xi_K, rms_slope, roughness_class, g, warnings.";
    auto fit_fn =
        [](py::handle ti, py::handle ts, py::handle ps, py::handle brightness, py::handle weight,
           const std::string& model, const std::string& correlation, const std::string& factor,
           const std::string& radiometry, const std::string& regime, double wavelength_um,
           const std::string& residual, const std::string& loss, double loss_scale,
           std::optional<double> initial_sigma_over_T, std::optional<double> initial_sigma_um,
           std::optional<double> initial_T_um, py::handle sigma_over_T_bounds,
           py::handle sigma_bounds_um, py::handle T_bounds_um, int max_iterations,
           bool scale_covariance, bool compare) -> py::dict {
        const auto ms = measurements_from(ti, ts, ps, brightness, weight);
        FitOptions o = fit_options_from(
            model, compare ? "gaussian" : correlation, factor, radiometry, regime, wavelength_um,
            residual, loss, loss_scale, initial_sigma_over_T, initial_sigma_um, initial_T_um,
            sigma_over_T_bounds, sigma_bounds_um, T_bounds_um, max_iterations, scale_covariance);
        if (!compare) {
            FitResult r;
            {
                py::gil_scoped_release release;
                r = fit_roughness(ms, o);
            }
            return fit_dict(r);
        }
        CorrelationComparison c;
        {
            py::gil_scoped_release release;
            c = compare_correlations(ms, o);
        }
        return py::dict(
            "gaussian"_a = fit_dict(c.gaussian), "exponential"_a = fit_dict(c.exponential),
            "preferred"_a = std::string(to_string(c.preferred)), "delta_aic"_a = c.delta_aic);
    };
    m.def(
        "fit_roughness",
        [fit_fn](py::handle ti, py::handle ts, py::handle ps, py::handle b, py::handle w,
                 const std::string& model, const std::string& correlation,
                 const std::string& factor, const std::string& radiometry,
                 const std::string& regime, double wavelength_um, const std::string& residual,
                 const std::string& loss, double loss_scale, std::optional<double> i_s,
                 std::optional<double> i_sigma, std::optional<double> i_T, py::handle sb,
                 py::handle sigb, py::handle tb, int max_iterations, bool scale_covariance) {
            return fit_fn(ti, ts, ps, b, w, model, correlation, factor, radiometry, regime,
                          wavelength_um, residual, loss, loss_scale, i_s, i_sigma, i_T, sb, sigb,
                          tb, max_iterations, scale_covariance, false);
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("brightness"),
        arg("weight") = py::none(), arg("model") = "very_rough", arg("correlation") = "gaussian",
        arg("factor") = "vh", arg("radiometry") = "radiance", arg("regime") = "slightly_rough",
        arg("wavelength_um") = 0.555, arg("residual") = "relative", arg("loss") = "none",
        arg("loss_scale") = 0.05, arg("initial_sigma_over_T") = py::none(),
        arg("initial_sigma_um") = py::none(), arg("initial_T_um") = py::none(),
        arg("sigma_over_T_bounds") = py::none(), arg("sigma_bounds_um") = py::none(),
        arg("T_bounds_um") = py::none(), arg("max_iterations") = 200,
        arg("scale_covariance") = true, fit_doc);
    m.def(
        "compare_correlations",
        [fit_fn](py::handle ti, py::handle ts, py::handle ps, py::handle b, py::handle w,
                 const std::string& model, const std::string& factor, const std::string& radiometry,
                 const std::string& regime, double wavelength_um, const std::string& residual,
                 const std::string& loss, double loss_scale) {
            return fit_fn(ti, ts, ps, b, w, model, "gaussian", factor, radiometry, regime,
                          wavelength_um, residual, loss, loss_scale, std::nullopt, std::nullopt,
                          std::nullopt, py::none(), py::none(), py::none(), 200, true, true);
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("brightness"),
        arg("weight") = py::none(), arg("model") = "very_rough", arg("factor") = "vh",
        arg("radiometry") = "radiance", arg("regime") = "slightly_rough",
        arg("wavelength_um") = 0.555, arg("residual") = "relative", arg("loss") = "none",
        arg("loss_scale") = 0.05,
        "Fits both correlation functions (see fit_roughness) and compares them by AIC: returns "
        "{'gaussian': fit, 'exponential': fit, 'preferred': name, 'delta_aic': AIC(other) - "
        "AIC(preferred)}.");
}

}  // namespace roughscope::python
