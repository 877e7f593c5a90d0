// The pybind11 extension module roughscope._core: error types, version, and every bind_* piece.
//
// Errors: every roughscope::Error becomes a Python exception deriving from ValueError, with the
// library's message unchanged:
//   roughscope.Error(ValueError)
//     ├── roughscope.InvalidArgument   (an input out of range, NaN, or inconsistent)
//     ├── roughscope.NoSolution        (an inversion with no solution for valid inputs)
//     └── roughscope.DataError         (a malformed or missing file or table)
#include <cstdint>
#include <optional>
#include <string>

#include <pybind11/pybind11.h>
#include <unistd.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/version.hpp"

namespace py = pybind11;

namespace roughscope::python {

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
    const auto ti = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
        np.attr("ravel")(b[0]));
    const auto ts = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
        np.attr("ravel")(b[1]));
    const auto ps = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
        np.attr("ravel")(b[2]));
    std::vector<Geometry> geoms;
    for (py::ssize_t i = 0; i < ti.size(); ++i)
        geoms.push_back(make_geometry(deg_to_rad(ti.data()[i]), deg_to_rad(ts.data()[i]),
                                      deg_to_rad(ps.data()[i])));
    return geoms;
}

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

std::string int_text(py::handle value) {
    const auto bits = value.attr("bit_length")().cast<long long>();
    if (bits <= 256) return py::str(value).cast<std::string>();
    return concat("an integer of ", std::to_string(bits), " bits");
}

namespace {

// Deepest nesting of dicts and sequences from_python follows: a self-referencing dict or list
// (d['rect'] = d) or a list nested 100,000 deep is refused with ValueError instead of
// exhausting the C++ stack. No option of the library nests more than a few levels.
constexpr int kMaxNesting = 32;

serialize::Json from_python_at(py::handle value, const std::string& where, int depth);

}  // namespace

serialize::Json from_python(py::handle value, const std::string& where) {
    return from_python_at(value, where, 0);
}

namespace {

serialize::Json from_python_at(py::handle value, const std::string& where, int depth) {
    using Json = serialize::Json;
    if (depth > kMaxNesting)
        throw py::value_error(concat(where, " is nested more than ", std::to_string(kMaxNesting),
                                     " levels deep (a dict or list that contains itself?)"));
    if (value.is_none()) return nullptr;
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
    if (py::isinstance<py::int_>(value)) {
        // JSON integers are int64 or uint64: a Python int in [-2^63, 2^64) (seeds up to 2^64 - 1).
        int overflow = 0;
        const long long signed_value = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
        if (overflow == 0 && !PyErr_Occurred()) return static_cast<std::int64_t>(signed_value);
        PyErr_Clear();
        if (overflow > 0) {
            const unsigned long long unsigned_value = PyLong_AsUnsignedLongLong(value.ptr());
            if (!PyErr_Occurred()) return static_cast<std::uint64_t>(unsigned_value);
            PyErr_Clear();
        }
        throw InvalidArgument(concat(where, " = ", int_text(value),
                                     " is out of range for an integer: it must be in "
                                     "[-2^63, 2^64)"));
    }
    if (py::isinstance<py::float_>(value)) return value.cast<double>();
    if (PyComplex_Check(value.ptr()) || py::isinstance<py::bytes>(value))
        throw py::type_error(where + " has an unsupported type " +
                             py::str(py::type::of(value).attr("__name__")).cast<std::string>() +
                             " (expected None, bool, an int or float, a string or a sequence)");
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    if (py::isinstance<py::dict>(value)) {
        Json out = Json::object();
        for (const auto& [k, v] : value.cast<py::dict>())
            out[py::str(k).cast<std::string>()] =
                from_python_at(v, where + " '" + py::str(k).cast<std::string>() + "'", depth + 1);
        return out;
    }
    if (py::hasattr(value, "tolist") && !py::isinstance<py::str>(value))  // numpy
        return from_python_at(value.attr("tolist")(), where, depth + 1);
    if (py::isinstance<py::sequence>(value)) {
        Json out = Json::array();
        for (py::handle item : value.cast<py::sequence>())
            out.push_back(from_python_at(item, where, depth + 1));
        return out;
    }
    throw py::type_error(where + " has an unsupported type " +
                         py::str(py::type::of(value).attr("__name__")).cast<std::string>() +
                         " (expected None, bool, an int or float, a string or a sequence)");
}

}  // namespace

namespace {

// The accepted dtype kinds: signed and unsigned integers, floating point.
bool real_kind(char kind) { return kind == 'i' || kind == 'u' || kind == 'f'; }

std::string type_name(py::handle value) {
    return py::str(py::type::of(value).attr("__name__")).cast<std::string>();
}

[[noreturn]] void not_real(const char* name, const std::string& what) {
    throw py::type_error(std::string(name) +
                         " must be a real number or an array-like of real numbers (int or "
                         "float, or a NumPy array of integer or floating dtype), not " +
                         what);
}

}  // namespace

py::object real_array(const char* name, py::handle value) {
    // Fast paths: an ndarray is checked by its dtype only; a Python float or int is taken as is.
    if (py::isinstance<py::array>(value)) {
        const py::dtype dt = py::reinterpret_borrow<py::array>(value).dtype();
        if (!real_kind(dt.kind()))
            not_real(name, "an array of dtype " +
                               py::str(static_cast<py::handle>(dt)).cast<std::string>());
        return py::reinterpret_borrow<py::object>(value);
    }
    if (value.is_none()) not_real(name, "None");
    if (PyBool_Check(value.ptr())) not_real(name, "bool");
    if (PyLong_Check(value.ptr())) {
        // An int beyond the double range (10**400) has no real value: named, not converted.
        (void)PyLong_AsDouble(value.ptr());
        if (PyErr_Occurred() != nullptr) {
            PyErr_Clear();
            throw InvalidArgument(concat(name, " = ", int_text(value),
                                         " is out of range for a real number (beyond 1.8e308)"));
        }
        return py::reinterpret_borrow<py::object>(value);
    }
    if (PyFloat_Check(value.ptr())) return py::reinterpret_borrow<py::object>(value);
    if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value) ||
        PyComplex_Check(value.ptr()))
        not_real(name, type_name(value));
    // NumPy scalars and sequences: by the dtype NumPy gives them.
    py::object array;
    try {
        array = py::module_::import("numpy").attr("asarray")(value);
    } catch (py::error_already_set& e) {
        if (e.matches(PyExc_MemoryError)) throw;
        // A ragged sequence: the values may be real, the shape is wrong.
        if (e.matches(PyExc_ValueError))
            throw InvalidArgument(std::string(name) +
                                  " is not a rectangular array of numbers: " + e.what());
        not_real(name, type_name(value) + " (" + e.what() + ")");
    }
    const py::dtype dt = py::reinterpret_borrow<py::array>(array).dtype();
    if (!real_kind(dt.kind())) {
        if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value))
            not_real(name, "a sequence of " +
                               py::str(static_cast<py::handle>(dt)).cast<std::string>() +
                               " values");
        not_real(name, type_name(value));
    }
    return array;
}

double real_scalar(const char* name, py::handle value) {
    if (PyFloat_Check(value.ptr())) return PyFloat_AS_DOUBLE(value.ptr());
    const py::object checked = real_array(name, value);
    const auto a = py::array_t<double, py::array::forcecast>::ensure(checked);
    if (!a) throw py::error_already_set();
    if (a.size() != 1)
        throw InvalidArgument(std::string(name) + " must be a single number, got an array of " +
                              std::to_string(a.size()) + " values");
    return a.data()[0];
}

std::optional<double> optional_real(const char* name, py::handle value) {
    if (value.is_none()) return std::nullopt;
    return real_scalar(name, value);
}

long long integer_scalar(const char* name, py::handle value) {
    // (NumPy's timedelta64 derives from its signedinteger: not an integer here.)
    const py::module_ np = py::module_::import("numpy");
    const bool integer =
        !PyBool_Check(value.ptr()) &&
        (PyLong_Check(value.ptr()) || (py::isinstance(value, np.attr("integer")) &&
                                       !py::isinstance(value, np.attr("timedelta64"))));
    if (!integer)
        throw py::type_error(std::string(name) +
                             " must be an integer (int or a NumPy integer), not " +
                             (value.is_none() ? std::string("None") : type_name(value)));
    const py::int_ v(py::reinterpret_borrow<py::object>(value));
    int overflow = 0;
    const long long n = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
    if (overflow != 0 || (n == -1 && PyErr_Occurred() != nullptr)) {
        PyErr_Clear();
        throw InvalidArgument(concat(name, " = ", int_text(v),
                                     " is out of range for an integer: it must be in "
                                     "[-2^63, 2^63 - 1] (and in the argument's own range)"));
    }
    return n;
}

std::string path_argument(const char* name, const std::string& path) {
    if (path.find('\0') != std::string::npos)
        throw py::value_error(concat(name, ": embedded null byte"));
    return path;
}

py::object real_option(const char* name, py::object value, bool pair, bool none_allowed) {
    if (value.is_none()) {
        if (!none_allowed) not_real(name, "None");
        return value;
    }
    if (pair && py::isinstance<py::array>(value)) real_array(name, value);  // dtype check
    if (pair && (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
                 py::isinstance<py::array>(value))) {
        py::list out;
        for (py::handle item : py::iter(value)) out.append(real_scalar(name, item));
        return out;
    }
    return py::float_(real_scalar(name, value));
}

void check_allocation(double elements, int arrays, const std::string& what) {
    const double bytes = elements * 8.0 * arrays;
    if (bytes < 1e8) return;  // the common case, without a system call
    static const double memory = [] {
        const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
        return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
    }();
    if (!(bytes <= 1e18) || (memory > 0.0 && bytes > memory)) {
        const std::string msg = what + " needs " + format_significant(bytes / 1073741824.0, 3) +
                                " GiB of float64 values, more than this machine's memory (" +
                                format_significant(memory / 1073741824.0, 3) +
                                " GiB): give smaller arrays";
        PyErr_SetString(PyExc_MemoryError, msg.c_str());
        throw py::error_already_set();
    }
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

    roughscope::python::bind_names_and_shared_data(m);
    roughscope::python::bind_geometry(m);
    roughscope::python::bind_scattering_vector(m);
    roughscope::python::bind_mean_scattered_power(m);
    roughscope::python::bind_diffuse_terms(m);
    roughscope::python::bind_retro_and_validity(m);
    roughscope::python::bind_reflectance_models(m);
    roughscope::python::bind_paper_tables(m);
    roughscope::python::bind_closed_form_estimators(m);
    roughscope::python::bind_two_geometry_solvers(m);
    roughscope::python::bind_estimates(m);
    roughscope::python::bind_fits(m);
    roughscope::python::bind_curet_database(m);
    roughscope::python::bind_brdf_tables(m);
    roughscope::python::bind_height_files(m);
    roughscope::python::bind_surface_analysis(m);
    roughscope::python::bind_simulation(m);
    roughscope::python::bind_capture(m);
    roughscope::python::bind_image(m);
    roughscope::python::bind_calibration(m);
    roughscope::python::bind_plan(m);
    roughscope::python::bind_photometric_stereo(m);
    roughscope::python::bind_report(m);
    roughscope::python::bind_documents(m);
}
