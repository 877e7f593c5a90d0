// roughscope._core: planning a capture — the pair of light zeniths with the smallest predicted
// u(σ/T) (measure/plan.hpp). The result is serialize/plan.hpp's dict, the JSON of `roughscope
// plan --json` (keys in docs/uncertainty.md "Planning a capture").
#include <optional>
#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/propagation.hpp"
#include "roughscope/measure/plan.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/serialize/plan.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

// A count: a Python or NumPy integer in [lo, hi].
std::size_t count_in(const char* name, py::handle value, long long lo, long long hi) {
    const long long v = integer_scalar(name, value);
    if (v < lo || v > hi)
        throw InvalidArgument(concat(name, " = ", std::to_string(v), " must be ",
                                     std::to_string(lo), " to ", std::to_string(hi)));
    return static_cast<std::size_t>(v);
}

// The capture file's "uncertainty" object as a dict: angle_deg, exposure_rel, black_level_dn,
// response_gamma, wavelength_um, flat_field_rel (others refused).
image::SetupTolerances tolerances_from(py::handle value) {
    image::SetupTolerances t;
    if (value.is_none()) return t;
    if (!py::isinstance<py::dict>(value))
        throw InvalidArgument("tolerances must be a dict of the capture file's uncertainty keys");
    for (const auto& [k, v] : py::reinterpret_borrow<py::dict>(value)) {
        const std::string key = py::str(k).cast<std::string>();
        const std::string name = concat("tolerances['", key, "']");
        std::optional<double>* slot = key == "angle_deg"        ? &t.angle_deg
                                      : key == "exposure_rel"   ? &t.exposure_rel
                                      : key == "black_level_dn" ? &t.black_level_dn
                                      : key == "response_gamma" ? &t.response_gamma
                                      : key == "wavelength_um"  ? &t.wavelength_um
                                      : key == "flat_field_rel" ? &t.flat_field_rel
                                                                : nullptr;
        if (!slot)
            throw InvalidArgument(
                concat("tolerances: key '", printable_text(key),
                       "' is not recognised; valid keys: angle_deg, exposure_rel, black_level_dn, "
                       "response_gamma, wavelength_um, flat_field_rel"));
        *slot = optional_real(name.c_str(), v);
    }
    return t;
}

}  // namespace

void bind_plan(py::module_& m) {
    m.def(
        "plan_capture",
        [](py::handle sigma_over_T, py::handle sigma_over_T_max, const std::string& correlation,
           py::handle tolerances, py::handle black_level_rel, py::handle full_scale_dn,
           py::handle noise_rel, py::handle fill, const std::string& exposure,
           const std::string& factor, py::handle theta_min_deg, py::handle theta_max_deg,
           py::handle theta_step_deg, py::handle min_difference_deg, py::handle range_points,
           py::handle top, const std::string& method) {
            image::PlanRequest r;
            r.sigma_over_T = real_scalar("sigma_over_T", sigma_over_T);
            r.sigma_over_T_max = optional_real("sigma_over_T_max", sigma_over_T_max);
            r.correlation = parse_correlation(correlation);
            r.tolerances = tolerances_from(tolerances);
            r.black_level_rel = optional_real("black_level_rel", black_level_rel);
            r.full_scale_dn = optional_real("full_scale_dn", full_scale_dn);
            r.noise_rel = real_scalar("noise_rel", noise_rel);
            r.fill = real_scalar("fill", fill);
            r.exposure = image::parse_plan_exposure(exposure);
            r.factor = parse_geometric_factor(factor);
            r.theta_min_deg = real_scalar("theta_min_deg", theta_min_deg);
            r.theta_max_deg = real_scalar("theta_max_deg", theta_max_deg);
            r.theta_step_deg = real_scalar("theta_step_deg", theta_step_deg);
            r.min_difference_deg = real_scalar("min_difference_deg", min_difference_deg);
            r.range_points = count_in("range_points", range_points, 2, 50);
            r.top = count_in("top", top, 1, 1000);
            r.propagation.method = parse_propagation_method(method);
            serialize::Json doc;
            {
                py::gil_scoped_release release;
                doc = serialize::to_json(image::plan_capture(r));
            }
            return to_python(doc);
        },
        py::arg("sigma_over_T"), py::arg("sigma_over_T_max") = py::none(),
        py::arg("correlation") = "gaussian", py::arg("tolerances") = py::none(),
        py::arg("black_level_rel") = py::none(), py::arg("full_scale_dn") = py::none(),
        py::arg("noise_rel") = 0.002, py::arg("fill") = 0.8, py::arg("exposure") = "per_capture",
        py::arg("factor") = "vh", py::arg("theta_min_deg") = 5.0, py::arg("theta_max_deg") = 75.0,
        py::arg("theta_step_deg") = 1.0, py::arg("min_difference_deg") = 5.0,
        py::arg("range_points") = 5, py::arg("top") = 10, py::arg("method") = "auto",
        "The pair of light zeniths theta1 < theta2 (camera on the normal) whose measurement of "
        "sigma/T has the smallest predicted standard uncertainty: at sigma_over_T, or the worst "
        "relative uncertainty over [sigma_over_T, sigma_over_T_max] (range_points points). "
        "tolerances: a dict of the capture file's uncertainty keys (angle_deg, exposure_rel; "
        "black_level_dn with full_scale_dn = W - b), unset ones the defaults; black_level_rel: "
        "u(b)/(W - b); noise_rel: relative noise of a region mean at `fill` of full scale; "
        "exposure: 'per_capture' (each capture at fill) or 'common'. Returns the dict of "
        "`roughscope plan --json`: recommended, paper_30_45, top, tolerances, assumed, grid, "
        "warnings (docs/uncertainty.md, 'Planning a capture').");
}

}  // namespace roughscope::python
