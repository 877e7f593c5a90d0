// The pybind11 extension module roughscope._core: error types, version, and every bind_* piece.
//
// Errors: every roughscope::Error becomes a Python exception deriving from ValueError, with the
// library's message unchanged:
//   roughscope.Error(ValueError)
//     ├── roughscope.InvalidArgument   (an input out of range, NaN, or inconsistent)
//     ├── roughscope.NoSolution        (an inversion with no solution for valid inputs)
//     └── roughscope.DataError         (a malformed or missing file or table)
#include <cstdint>
#include <string>

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/version.hpp"

namespace py = pybind11;

namespace roughscope::python {

py::object to_python(const serialize::Json& value) {
    using Json = serialize::Json;
    switch (value.type()) {
        case Json::value_t::null:
        case Json::value_t::discarded:
            return py::none();
        case Json::value_t::boolean:
            return py::bool_(value.get<bool>());
        case Json::value_t::number_integer:
            return py::int_(value.get<std::int64_t>());
        case Json::value_t::number_unsigned:
            return py::int_(value.get<std::uint64_t>());
        case Json::value_t::number_float:
            return py::float_(value.get<double>());
        case Json::value_t::string:
            return py::str(value.get_ref<const std::string&>());
        case Json::value_t::array: {
            py::list out;
            for (const Json& item : value) out.append(to_python(item));
            return out;
        }
        case Json::value_t::object: {
            py::dict out;
            for (const auto& [key, item] : value.items()) out[py::str(key)] = to_python(item);
            return out;
        }
        case Json::value_t::binary:
            break;
    }
    throw Error("to_python: unsupported JSON value");
}

serialize::Json from_python(py::handle value, const std::string& where) {
    using Json = serialize::Json;
    if (value.is_none()) return nullptr;
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
    if (py::isinstance<py::int_>(value)) return value.cast<std::int64_t>();
    if (py::isinstance<py::float_>(value)) return value.cast<double>();
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    if (py::isinstance<py::dict>(value)) {
        Json out = Json::object();
        for (const auto& [k, v] : value.cast<py::dict>())
            out[py::str(k).cast<std::string>()] =
                from_python(v, where + " '" + py::str(k).cast<std::string>() + "'");
        return out;
    }
    if (py::hasattr(value, "tolist") && !py::isinstance<py::str>(value))  // numpy
        return from_python(value.attr("tolist")(), where);
    if (py::isinstance<py::sequence>(value)) {
        Json out = Json::array();
        for (py::handle item : value.cast<py::sequence>()) out.push_back(from_python(item, where));
        return out;
    }
    throw InvalidArgument(where + " has an unsupported type " +
                          py::str(py::type::of(value).attr("__name__")).cast<std::string>() +
                          " (expected None, bool, a number, a string or a sequence)");
}

}  // namespace roughscope::python

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
