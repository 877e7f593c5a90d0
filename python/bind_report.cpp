// Bindings of the small library functions the pure-Python figures and report draw with, so that
// roughscope/ (report, figures) computes no physics of its own: the sRGB transfer curve a
// photograph is shown with (core/response.hpp) and the model autocorrelation functions of §3.1
// drawn over a measured ACF (surface/statistics.hpp).
//
// Same boundary conventions as the rest of the module (docs/python.md): array-like arguments
// broadcast with NumPy's rules, a float for scalar arguments, a roughscope.Error (ValueError)
// naming the input and its valid range for a bad value.
#include <cmath>
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/response.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/surface/statistics.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

// A checked numeric argument as a float64 array (real_array: TypeError for a non-real type).
py::array_t<double> real_doubles(const char* name, py::handle value) {
    return py::array_t<double, py::array::forcecast>::ensure(real_array(name, value));
}

// Two checked numeric arguments broadcast together with NumPy's rules (views, no copy):
// InvalidArgument when their shapes do not broadcast, MemoryError (before allocating) when the
// result would not fit in memory.
std::pair<py::array_t<double>, py::array_t<double>> broadcast_pair(const char* name_a, py::handle a,
                                                                   const char* name_b,
                                                                   py::handle b) {
    const py::object np = py::module_::import("numpy");
    const py::object x = real_doubles(name_a, a);
    const py::object y = real_doubles(name_b, b);
    py::list both;
    try {
        both = np.attr("broadcast_arrays")(x, y);
    } catch (const py::error_already_set&) {
        throw InvalidArgument(std::string(name_a) + " and " + name_b +
                              " cannot be broadcast together");
    }
    const py::array first = py::array::ensure(both[0]);
    check_allocation(static_cast<double>(first.size()), 1,
                     "a result of shape " + py::str(first.attr("shape")).cast<std::string>());
    return {real_doubles(name_a, both[0]), real_doubles(name_b, both[1])};
}

}  // namespace

void bind_report(py::module_& m) {
    m.def(
        "srgb_encode",
        [](py::handle linear) {
            auto encode = py::vectorize([](double u) {
                if (!(u >= 0.0 && u <= 1.0))
                    throw InvalidArgument("linear = " + check::format_number(u) +
                                          " is outside the valid range [0, 1]");
                return srgb_encode(u);
            });
            return encode(real_doubles("linear", linear));
        },
        py::arg("linear"),
        R"doc(IEC 61966-2-1 sRGB encoding of linear values u in [0, 1] (the curve the synthetic
captures and sRGB photographs use, core/response.hpp): 12.92 u for u <= 0.0031308, else
1.055 u^(1/2.4) − 0.055. Array-like in, float or array out.)doc");

    m.def(
        "acf_model",
        [](py::handle lag_um, py::handle T_um, const std::string& correlation) {
            const Correlation c = parse_correlation(correlation);
            auto model = py::vectorize([c](double lag, double T) {
                check::finite("lag_um", lag);
                check::positive("T_um", T, "um");
                return surface::acf_model(c, lag, T);
            });
            const auto [lag, T] = broadcast_pair("lag_um", lag_um, "T_um", T_um);
            return model(lag, T);
        },
        py::arg("lag_um"), py::arg("T_um"), py::arg("correlation") = "gaussian",
        R"doc(The model autocorrelation function of §3.1 at lag τ (µm) for a correlation length
T > 0 (µm): exp(−τ²/T²) for correlation="gaussian", exp(−|τ|/T) for "exponential" (the curves
surface_statistics fits to a measured ACF). Array-like arguments broadcast together.)doc");
}

}  // namespace roughscope::python
