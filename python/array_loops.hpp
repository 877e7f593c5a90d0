// Array arguments of the vectorised bindings (bind_core.cpp, bind_power.cpp, bind_models.cpp):
// NumPy broadcasting of numeric arguments, parallel loops without the GIL that report the first
// bad element (C order) with its index, and the small conversions those bindings share.
//
// Conventions at this boundary (docs/python.md):
//  * angles in degrees (`_deg`), lengths in micrometres (`_um`); radians only inside the library;
//  * every numeric argument is array-like and broadcast with NumPy's rules; when every numeric
//    argument is a scalar (Python number or 0-d array) the result is a Python float (bool, str),
//    otherwise a NumPy array of the broadcast shape;
//  * validation is the library's: a bad element raises a roughscope.Error subclass (ValueError)
//    whose message names the input, its value, the valid range and, for arrays, the element's
//    index ("at index 3: ..."). The first bad element (in C order) is the one reported.
//  * loops run without the GIL, in parallel over chunks for large arrays.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // std::vector <-> list in py::cast (shapes, names)

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::python {

namespace py = ::pybind11;
using ssize_t = ::pybind11::ssize_t;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// =============================================================================================
// Broadcasting of array-like arguments
// =============================================================================================

// One numeric argument after conversion: element i of the broadcast result is data[i * step]
// (step = 0 for a value repeated over the result, `inner` for one value per element).
struct Operand {
    DoubleArray array;  // keeps the buffer alive
    const double* data = nullptr;
    ssize_t step = 0;
};

struct Broadcast {
    std::vector<ssize_t> shape;  // broadcast shape (without the inner dimension of vectors)
    ssize_t size = 1;            // number of elements
    bool scalar = true;          // every argument was 0-d (or a single vector for (..., 3))
};

// "(2, 3)", "(4,)": a shape as NumPy prints it.
std::string shape_string(const std::vector<ssize_t>& shape);

// A numeric argument as contiguous float64 (no copy for a float64 C-contiguous array): TypeError
// for a non-real type (real_array, bindings.hpp); the conversion of a real array can only fail
// for want of memory.
DoubleArray to_double_array(const char* name, py::handle value);

// Converts `values` to contiguous double arrays and broadcasts them together. With inner = 3 each
// argument must have shape (..., 3) and the leading dimensions are broadcast.
template <std::size_t N>
std::pair<std::array<Operand, N>, Broadcast> broadcast(const std::array<const char*, N>& names,
                                                       const std::array<py::handle, N>& values,
                                                       ssize_t inner = 1) {
    std::array<Operand, N> ops;
    std::array<std::vector<ssize_t>, N> shapes;
    Broadcast b;
    std::size_t ndim = 0;
    for (std::size_t k = 0; k < N; ++k) {
        ops[k].array = to_double_array(names[k], values[k]);
        const auto& a = ops[k].array;
        std::vector<ssize_t> s(a.shape(), a.shape() + a.ndim());
        if (inner > 1) {
            if (s.empty() || s.back() != inner)
                throw InvalidArgument(std::string(names[k]) + " must have shape (..., " +
                                      std::to_string(inner) + "), got " + shape_string(s));
            s.pop_back();
        }
        if (!s.empty()) b.scalar = false;
        ndim = std::max(ndim, s.size());
        shapes[k] = std::move(s);
    }
    b.shape.assign(ndim, 1);
    for (std::size_t k = 0; k < N; ++k) {
        const std::size_t offset = ndim - shapes[k].size();
        for (std::size_t d = 0; d < shapes[k].size(); ++d) {
            ssize_t& r = b.shape[offset + d];
            const ssize_t n = shapes[k][d];
            if (r == 1) {
                r = n;
            } else if (n != 1 && n != r) {
                std::string msg = "arguments cannot be broadcast together:";
                for (std::size_t j = 0; j < N; ++j)
                    msg += std::string(j ? ", " : " ") + names[j] + " " + shape_string(shapes[j]);
                throw InvalidArgument(msg);
            }
        }
    }
    // The result's size, checked before anything of that size is allocated (in double: the
    // product of the dimensions may overflow ssize_t).
    double elements = 1.0;
    for (ssize_t n : b.shape) elements *= static_cast<double>(n);
    if (elements * static_cast<double>(inner) * 8.0 >= 1e8)
        check_allocation(elements * static_cast<double>(inner), 1,
                         "the broadcast result of shape " + shape_string(b.shape));
    b.size = 1;
    for (ssize_t n : b.shape) b.size *= n;

    for (std::size_t k = 0; k < N; ++k) {
        ssize_t count = 1;
        for (ssize_t n : shapes[k]) count *= n;
        if (count != b.size && count != 1) {
            // Neither one value per element nor one value for all: materialise the broadcast.
            std::vector<ssize_t> full = b.shape;
            if (inner > 1) full.push_back(inner);
            py::object view = py::module_::import("numpy").attr("broadcast_to")(
                ops[k].array, py::tuple(py::cast(full)));
            ops[k].array = to_double_array(names[k], view);
            count = b.size;
        }
        // count == b.size: every dimension equals the broadcast one, so C order matches.
        ops[k].step = (count == b.size && b.size != 1) ? inner : 0;
        ops[k].data = ops[k].array.data();
    }
    return {std::move(ops), std::move(b)};
}
// The result for a broadcast: a Python float for all-scalar input, else the array.
py::object finish(const Broadcast& b, py::array_t<double>& out);

// An uninitialised float64 array of the broadcast shape.
py::array_t<double> make_output(const Broadcast& b);

// str (all-scalar input) or a NumPy str array from small integer codes into `names`.
py::object names_from_codes(const Broadcast& b, py::array_t<std::uint8_t>& codes,
                            const std::vector<std::string>& names);

// =============================================================================================
// Loops: chunks run without the GIL; the first failing element (C order) is reported.
// =============================================================================================

// The index of flat element `flat` of the broadcast result: "3" or "(1, 2)".
std::string index_string(const Broadcast& b, ssize_t flat);

// Rethrows `error` with the element's index prefixed to the message, keeping the type.
[[noreturn]] void rethrow_at(const Broadcast& b, ssize_t index, std::exception_ptr error);

// Caps the worker threads of array loops (0: one per hardware thread, at most 8).
void set_max_worker_threads(int n);

// Worker threads for n elements, at least min_chunk elements each.
int worker_count(ssize_t n, ssize_t min_chunk);

// Runs chunk(begin, end, at) over [0, n) split in `workers` chunks, without the GIL. A chunk that
// throws must leave `at` at the failing element. Rethrows the failure of the earliest chunk,
// i.e. the first bad element in C order.
template <class Chunk>
void run_chunks(const Broadcast& b, int workers, Chunk&& chunk) {
    const ssize_t n = b.size;
    if (n == 0) return;
    workers = std::max(1, workers);
    std::vector<ssize_t> failed_at(workers, -1);
    std::vector<std::exception_ptr> errors(workers);
    auto run = [&](int w) {
        const ssize_t begin = n * w / workers, end = n * (w + 1) / workers;
        ssize_t at = begin;
        try {
            chunk(begin, end, at);
        } catch (...) {
            failed_at[w] = at;
            errors[w] = std::current_exception();
        }
    };
    {
        py::gil_scoped_release release;
        std::vector<std::thread> threads;
        threads.reserve(workers - 1);
        for (int w = 1; w < workers; ++w) threads.emplace_back(run, w);
        run(0);
        for (auto& t : threads) t.join();
    }
    for (int w = 0; w < workers; ++w)
        if (errors[w]) rethrow_at(b, failed_at[w], errors[w]);
}

// For each element: f(i) (reads the operands at i, writes outputs at i).
template <class F>
void for_each_element(const Broadcast& b, bool parallel, F&& f) {
    const int workers = parallel ? worker_count(b.size, 4096) : 1;
    run_chunks(b, workers, [&](ssize_t begin, ssize_t end, ssize_t& at) {
        for (at = begin; at < end; ++at) f(at);
    });
}

template <std::size_t N>
std::array<double, N> values_at(const std::array<Operand, N>& ops, ssize_t i) {
    std::array<double, N> x;
    for (std::size_t k = 0; k < N; ++k) x[k] = ops[k].data[i * ops[k].step];
    return x;
}

// The workhorse: out[i] = f(x0[i], x1[i], ...), broadcast, float for scalars.
template <std::size_t N, class F>
py::object map_double(const std::array<const char*, N>& names,
                      const std::array<py::handle, N>& values, F f, bool parallel = true) {
    auto operands = broadcast<N>(names, values);
    auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
    auto& b = operands.second;
    py::array_t<double> out = make_output(b);
    double* o = out.mutable_data();
    for_each_element(b, parallel, [&](ssize_t i) { o[i] = std::apply(f, values_at(ops, i)); });
    return finish(b, out);
}

// ---------------------------------------------------------------------------------------------
// Small helpers

// The geometry of three angles in degrees (make_geometry checks them).
Geometry geometry_deg(double theta_i_deg, double theta_s_deg, double phi_s_deg);

template <class Enum, std::size_t K>
std::vector<std::string> enum_names(const std::array<Enum, K>& values) {
    std::vector<std::string> names;
    names.reserve(K);
    for (Enum e : values) names.emplace_back(to_string(e));
    return names;
}

inline constexpr std::array<Correlation, 2> kCorrelations = {Correlation::Gaussian,
                                                             Correlation::Exponential};
inline constexpr std::array<GeometricFactor, 4> kFactors = {
    GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey, GeometricFactor::Ogilvy,
    GeometricFactor::Kirchhoff};
inline constexpr std::array<Radiometry, 2> kRadiometries = {Radiometry::Radiance,
                                                            Radiometry::Intensity};
inline constexpr std::array<Regime, 5> kRegimes = {Regime::Auto, Regime::Series,
                                                   Regime::SlightlyRough, Regime::VeryRough,
                                                   Regime::VeryRoughSeriesLimit};
inline constexpr std::array<DiffuseMethod, 3> kMethods = {
    DiffuseMethod::ClosedForm, DiffuseMethod::Summation, DiffuseMethod::LargeGExpansion};
inline constexpr std::array<RoughnessClass, 3> kRoughnessClasses = {
    RoughnessClass::SlightlyRough, RoughnessClass::ModeratelyRough, RoughnessClass::VeryRough};

// The unchecked pure terms (diffuse_power_*) overflow for extreme combinations of their inputs:
// an InvalidArgument (ValueError) instead of inf or NaN.
double representable(double value);

// The position of `value` in `values` as a small code for names_from_codes.
template <class Enum, std::size_t K>
std::uint8_t code_of(const std::array<Enum, K>& values, Enum value) {
    return static_cast<std::uint8_t>(std::find(values.begin(), values.end(), value) -
                                     values.begin());
}

}  // namespace roughscope::python
