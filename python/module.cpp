// The pybind11 extension module roughscope._core: error types, version, and every bind_* piece.
//
// Errors: every roughscope::Error becomes a Python exception deriving from ValueError, with the
// library's message unchanged:
//   roughscope.Error(ValueError)
//     ├── roughscope.InvalidArgument   (an input out of range, NaN, or inconsistent)
//     ├── roughscope.NoSolution        (an inversion with no solution for valid inputs)
//     └── roughscope.DataError         (a malformed or missing file or table)
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/version.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
    m.doc() =
        "roughscope._core: compiled bindings of the roughscope C++ library (Ragheb & Hancock, "
        "'The modified Beckmann-Kirchhoff scattering theory for rough surface analysis', 2007). "
        "Angles in degrees (_deg), lengths in micrometres (_um). Import the package "
        "'roughscope' rather than this module.";

    // Base first, derived after: pybind11 tries translators newest-first, so a derived C++
    // exception is matched by its own Python class before the base's.
    auto error = py::register_exception<roughscope::Error>(m, "Error", PyExc_ValueError);
    auto invalid =
        py::register_exception<roughscope::InvalidArgument>(m, "InvalidArgument", error.ptr());
    auto no_solution = py::register_exception<roughscope::NoSolution>(m, "NoSolution", error.ptr());
    auto data_error = py::register_exception<roughscope::DataError>(m, "DataError", error.ptr());

    // Show them as roughscope.Error etc. (the package re-exports them).
    error.attr("__module__") = "roughscope";
    invalid.attr("__module__") = "roughscope";
    no_solution.attr("__module__") = "roughscope";
    data_error.attr("__module__") = "roughscope";
    error.doc() = "Base of every error raised by roughscope (a ValueError).";
    invalid.doc() = "An argument is outside its valid range, NaN, or inconsistent with another.";
    no_solution.doc() =
        "The inputs are valid but the equation being inverted has no solution for them.";
    data_error.doc() = "A file or table is malformed or missing.";

    m.attr("__version__") = ROUGHSCOPE_VERSION_STRING;

    roughscope::python::bind_core(m);
    roughscope::python::bind_estimation(m);
    roughscope::python::bind_curet(m);
}
