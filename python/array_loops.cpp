// Array arguments of the vectorised bindings: the non-template part of array_loops.hpp.
#include "array_loops.hpp"

#include <atomic>
#include <cmath>

namespace roughscope::python {

std::string shape_string(const std::vector<ssize_t>& shape) {
    std::string s = "(";
    for (std::size_t k = 0; k < shape.size(); ++k) {
        if (k) s += ", ";
        s += std::to_string(shape[k]);
    }
    if (shape.size() == 1) s += ",";
    return s + ")";
}

DoubleArray to_double_array(const char* name, py::handle value) {
    DoubleArray array = DoubleArray::ensure(real_array(name, value));
    if (!array) {
        PyErr_SetString(PyExc_MemoryError,
                        (std::string(name) + ": no memory for its float64 copy").c_str());
        throw py::error_already_set();
    }
    return array;
}

py::object finish(const Broadcast& b, py::array_t<double>& out) {
    if (b.scalar) return py::float_(out.data()[0]);
    return std::move(out);
}

py::array_t<double> make_output(const Broadcast& b) { return py::array_t<double>(b.shape); }

py::object names_from_codes(const Broadcast& b, py::array_t<std::uint8_t>& codes,
                            const std::vector<std::string>& names) {
    if (b.scalar) return py::str(names.at(codes.data()[0]));
    py::object table = py::module_::import("numpy").attr("array")(py::cast(names));
    return table[codes];
}

std::string index_string(const Broadcast& b, ssize_t flat) {
    if (b.shape.size() == 1) return std::to_string(flat);
    std::vector<ssize_t> idx(b.shape.size());
    for (std::size_t d = b.shape.size(); d-- > 0;) {
        idx[d] = b.shape[d] ? flat % b.shape[d] : 0;
        flat = b.shape[d] ? flat / b.shape[d] : 0;
    }
    std::string s = "(";
    for (std::size_t d = 0; d < idx.size(); ++d) s += (d ? ", " : "") + std::to_string(idx[d]);
    return s + ")";
}

[[noreturn]] void rethrow_at(const Broadcast& b, ssize_t index, std::exception_ptr error) {
    if (b.scalar || index < 0) std::rethrow_exception(error);
    const std::string where = "at index " + index_string(b, index) + ": ";
    try {
        std::rethrow_exception(error);
    } catch (const NoSolution& e) {
        throw NoSolution(where + e.what());
    } catch (const DataError& e) {
        throw DataError(where + e.what());
    } catch (const InvalidArgument& e) {
        throw InvalidArgument(where + e.what());
    } catch (const Error& e) {
        throw Error(where + e.what());
    }
}

namespace {

// Upper bound on worker threads (0: one per hardware thread, at most 8); see _set_max_threads.
std::atomic<int> g_max_threads{0};

}  // namespace

void set_max_worker_threads(int n) { g_max_threads.store(n); }

int worker_count(ssize_t n, ssize_t min_chunk) {
    unsigned hw = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
    if (const int cap = g_max_threads.load(); cap > 0) hw = std::min<unsigned>(hw, cap);
    const ssize_t by_size = std::max<ssize_t>(1, n / std::max<ssize_t>(1, min_chunk));
    return static_cast<int>(std::min<ssize_t>(hw, by_size));
}

Geometry geometry_deg(double theta_i_deg, double theta_s_deg, double phi_s_deg) {
    return make_geometry(deg_to_rad(theta_i_deg), deg_to_rad(theta_s_deg), deg_to_rad(phi_s_deg));
}

double representable(double value) {
    if (!std::isfinite(value))
        throw InvalidArgument(
            "the result is not representable as a double for these inputs (it overflows or is "
            "0/0); keep the lengths in [1e-30, 1e30] um as mean_scattered_power does");
    return value;
}

}  // namespace roughscope::python
