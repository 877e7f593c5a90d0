// Vectorised Python bindings of the core API (paper §2–3): geometry, scattering vector, geometric
// factors, the B–K mean scattered power (Eq. 1–5), retro-scattering forms (Eq. 7–11), validity
// (§3.5) and the comparison models of §5.
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
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "roughscope/io/data_locator.hpp"
#include "roughscope/roughscope.hpp"
#include "roughscope/scattering/brightness_batch.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

using py::ssize_t;
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

std::string shape_string(const std::vector<ssize_t>& shape) {
    std::string s = "(";
    for (std::size_t k = 0; k < shape.size(); ++k) {
        if (k) s += ", ";
        s += std::to_string(shape[k]);
    }
    if (shape.size() == 1) s += ",";
    return s + ")";
}

// A numeric argument as contiguous float64 (no copy for a float64 C-contiguous array): TypeError
// for a non-real type (real_array, bindings.hpp); the conversion of a real array can only fail
// for want of memory.
DoubleArray to_double_array(const char* name, py::handle value) {
    DoubleArray array = DoubleArray::ensure(real_array(name, value));
    if (!array) {
        PyErr_SetString(PyExc_MemoryError,
                        (std::string(name) + ": no memory for its float64 copy").c_str());
        throw py::error_already_set();
    }
    return array;
}

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
py::object finish(const Broadcast& b, py::array_t<double>& out) {
    if (b.scalar) return py::float_(out.data()[0]);
    return std::move(out);
}

py::array_t<double> make_output(const Broadcast& b) { return py::array_t<double>(b.shape); }

// str (all-scalar input) or a NumPy str array from small integer codes into `names`.
py::object names_from_codes(const Broadcast& b, py::array_t<std::uint8_t>& codes,
                            const std::vector<std::string>& names) {
    if (b.scalar) return py::str(names.at(codes.data()[0]));
    py::object table = py::module_::import("numpy").attr("array")(py::cast(names));
    return table[codes];
}

// =============================================================================================
// Loops: chunks run without the GIL; the first failing element (C order) is reported.
// =============================================================================================

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

// Rethrows `error` with the element's index prefixed to the message, keeping the type.
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

// Upper bound on worker threads (0: one per hardware thread, at most 8); see _set_max_threads.
std::atomic<int> g_max_threads{0};

int worker_count(ssize_t n, ssize_t min_chunk) {
    unsigned hw = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
    if (const int cap = g_max_threads.load(); cap > 0) hw = std::min<unsigned>(hw, cap);
    const ssize_t by_size = std::max<ssize_t>(1, n / std::max<ssize_t>(1, min_chunk));
    return static_cast<int>(std::min<ssize_t>(hw, by_size));
}

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

Geometry geometry_deg(double theta_i_deg, double theta_s_deg, double phi_s_deg) {
    return make_geometry(deg_to_rad(theta_i_deg), deg_to_rad(theta_s_deg), deg_to_rad(phi_s_deg));
}

template <class Enum, std::size_t K>
std::vector<std::string> enum_names(const std::array<Enum, K>& values) {
    std::vector<std::string> names;
    names.reserve(K);
    for (Enum e : values) names.emplace_back(to_string(e));
    return names;
}

constexpr std::array<Correlation, 2> kCorrelations = {Correlation::Gaussian,
                                                      Correlation::Exponential};
constexpr std::array<GeometricFactor, 4> kFactors = {
    GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey, GeometricFactor::Ogilvy,
    GeometricFactor::Kirchhoff};
constexpr std::array<Radiometry, 2> kRadiometries = {Radiometry::Radiance, Radiometry::Intensity};
constexpr std::array<Regime, 5> kRegimes = {Regime::Auto, Regime::Series, Regime::SlightlyRough,
                                            Regime::VeryRough, Regime::VeryRoughSeriesLimit};
constexpr std::array<DiffuseMethod, 3> kMethods = {
    DiffuseMethod::ClosedForm, DiffuseMethod::Summation, DiffuseMethod::LargeGExpansion};
constexpr std::array<RoughnessClass, 3> kRoughnessClasses = {
    RoughnessClass::SlightlyRough, RoughnessClass::ModeratelyRough, RoughnessClass::VeryRough};

// The unchecked pure terms (diffuse_power_*) overflow for extreme combinations of their inputs:
// an InvalidArgument (ValueError) instead of inf or NaN.
double representable(double value) {
    if (!std::isfinite(value))
        throw InvalidArgument(
            "the result is not representable as a double for these inputs (it overflows or is "
            "0/0); keep the lengths in [1e-30, 1e30] um as mean_scattered_power does");
    return value;
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

// =============================================================================================
// Lafortune lobes from Python
// =============================================================================================

std::vector<LafortuneLobe> lobes_from_python(py::handle lobes) {
    std::vector<LafortuneLobe> result;
    // One dict is one lobe; the list made of it is held here (a handle alone would dangle).
    py::object held = py::reinterpret_borrow<py::object>(lobes);
    if (py::isinstance<py::dict>(lobes)) held = py::list(py::make_tuple(lobes));
    lobes = held;
    bool sequence_of_dicts = py::isinstance<py::sequence>(lobes) && !py::isinstance<py::str>(lobes);
    if (sequence_of_dicts) {
        auto seq = py::reinterpret_borrow<py::sequence>(lobes);
        for (py::handle item : seq)
            if (!py::isinstance<py::dict>(item)) sequence_of_dicts = false;
        if (sequence_of_dicts && py::len(seq) > 0) {
            std::size_t index = 0;
            for (py::handle item : seq) {
                auto d = py::reinterpret_borrow<py::dict>(item);
                LafortuneLobe lobe;
                for (auto kv : d) {
                    const std::string key = py::str(kv.first);
                    // TypeError for a non-real value, InvalidArgument (ValueError) for an array.
                    const std::string where = "lobes[" + std::to_string(index) + "]['" + key + "']";
                    const double v = real_scalar(where.c_str(), kv.second);
                    if (key == "Cx")
                        lobe.Cx = v;
                    else if (key == "Cy")
                        lobe.Cy = v;
                    else if (key == "Cz")
                        lobe.Cz = v;
                    else if (key == "n")
                        lobe.n = v;
                    else if (key == "albedo" || key == "rho")
                        lobe.albedo = v;
                    else
                        throw InvalidArgument("lobes: unknown key '" + key +
                                              "' (expected Cx, Cy, Cz, n, albedo)");
                }
                result.push_back(lobe);
                ++index;
            }
            return result;
        }
    }
    DoubleArray a = to_double_array("lobes", lobes);
    if (a.ndim() == 1 && a.shape(0) == 5) a = to_double_array("lobes", a.reshape({1, 5}));
    if (a.ndim() != 2 || a.shape(1) != 5)
        throw InvalidArgument(
            "lobes must be a list of dicts (Cx, Cy, Cz, n, albedo) or an array "
            "of shape (N, 5) with columns Cx, Cy, Cz, n, albedo; got shape " +
            shape_string({a.shape(), a.shape() + a.ndim()}));
    for (ssize_t k = 0; k < a.shape(0); ++k) {
        const double* row = a.data() + 5 * k;
        result.push_back(LafortuneLobe{row[0], row[1], row[2], row[3], row[4]});
    }
    return result;
}

}  // namespace

// =============================================================================================
// Module definitions
// =============================================================================================

void bind_core(py::module_& m) {
    using py::arg;

    m.attr("CORRELATIONS") = py::tuple(py::cast(enum_names(kCorrelations)));
    m.attr("FACTORS") = py::tuple(py::cast(enum_names(kFactors)));
    m.attr("RADIOMETRIES") = py::tuple(py::cast(enum_names(kRadiometries)));
    m.attr("REGIMES") = py::tuple(py::cast(enum_names(kRegimes)));
    m.attr("ROUGHNESS_CLASSES") = py::tuple(py::cast(enum_names(kRoughnessClasses)));
    m.attr("SLIGHTLY_ROUGH_MAX_G") = kSlightlyRoughMaxG;
    m.attr("VERY_ROUGH_MIN_G") = kVeryRoughMinG;

    // ---- Reference data beside the project (io/data_locator.hpp) ----------------------------
    using Starts = std::vector<std::filesystem::path>;
    m.def(
        "shared_dir_candidates",
        [](const Starts& extra_starts) { return io::shared_dir_candidates(extra_starts); },
        arg("extra_starts") = Starts{},
        "The shared folders searched, in order: $ROUGHSCOPE_SHARED_DIR alone when set, else "
        "../shared from the current directory upward, then from each of extra_starts.");
    m.def(
        "find_shared",
        [](const std::string& relative, const Starts& extra_starts) {
            return io::find_shared(relative, extra_starts);
        },
        arg("relative"), arg("extra_starts") = Starts{},
        "Path of `relative` in the first shared folder holding it, or None.");
    m.def(
        "paper_tables_path",
        [](const Starts& extra_starts) { return io::paper_tables_path(extra_starts); },
        arg("extra_starts") = Starts{},
        "Path of reference/paper-tables.json in the shared folder, or None.");
    m.def(
        "curet_data_dir",
        [](const Starts& extra_starts) { return io::curet_data_dir(extra_starts); },
        arg("extra_starts") = Starts{},
        "The shared folder's data/curet (holding table.txt and abrdf.dat), or None.");
    m.def(
        "shared_search_description",
        [](const std::string& relative) { return io::shared_search_description(relative); },
        arg("relative"), "One line saying where `relative` is looked for.");
    m.def("shared_data_required", &io::shared_data_required,
          "True when ROUGHSCOPE_REQUIRE_SHARED_DATA=1: tests must fail, not skip, when the "
          "shared data are missing.");

    // ---- Private knobs for tests and benchmarks ---------------------------------------------
    m.def(
        "_set_vector_isa",
        [](const std::string& name) {
            return std::string(to_string(set_vector_isa_cap(parse_vector_isa(name))));
        },
        arg("isa"),
        "Testing aid: cap the instruction set of the array kernels ('generic', 'avx2', "
        "'avx512' or 'best'); returns the one now in use (never above what the CPU has).");
    m.def(
        "_set_max_threads",
        [](int n) {
            if (n < 0)
                throw InvalidArgument("max_threads = " + std::to_string(n) + " must be >= 0");
            g_max_threads.store(n);
        },
        arg("n"), "Benchmark aid: cap the worker threads of array loops (0: no cap).");

    // ---- Geometry (§2) --------------------------------------------------------------------
    m.def(
        "geometry_from_vectors",
        [](py::handle N, py::handle L, py::handle V, py::handle unit_tolerance_in) {
            const double unit_tolerance = real_scalar("unit_tolerance", unit_tolerance_in);
            auto operands = broadcast<3>({"N", "L", "V"}, {N, L, V}, 3);
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> ti = make_output(b), ts = make_output(b), ps = make_output(b);
            py::array_t<bool> visible(b.shape);
            double *oi = ti.mutable_data(), *os = ts.mutable_data(), *op = ps.mutable_data();
            bool* ov = visible.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                auto vec = [&](int k) {
                    const double* p = ops[k].data + i * ops[k].step;
                    return Eigen::Vector3d(p[0], p[1], p[2]);
                };
                const std::optional<Geometry> g =
                    geometry_from_vectors(vec(0), vec(1), vec(2), unit_tolerance);
                ov[i] = g.has_value();
                oi[i] = g ? rad_to_deg(g->theta_i_rad) : 0.0;
                os[i] = g ? rad_to_deg(g->theta_s_rad) : 0.0;
                op[i] = g ? rad_to_deg(g->phi_s_rad) : 0.0;
            });
            if (b.scalar) return py::make_tuple(oi[0], os[0], op[0], py::bool_(ov[0]));
            return py::make_tuple(ti, ts, ps, visible);
        },
        arg("N"), arg("L"), arg("V"), arg("unit_tolerance") = 1e-6,
        R"doc(Imaging geometry from the surface normal N, light direction L and viewing direction V
(paper §2, Fig. 2): θi = acos(N·L), θs = acos(N·V), φs = π − angle between the
tangent-plane projections of L and V (so φs = 0 is the specular plane, 180 retro).

N, L, V: unit vectors, array-likes of shape (..., 3), broadcast over the leading dimensions;
they must be finite and of unit length within unit_tolerance (else roughscope.InvalidArgument).
L and V point away from the surface.

Returns (theta_i_deg, theta_s_deg, phi_s_deg, visible). phi_s_deg is in [0, 180]. Where L or
V is at or below the horizon (N·L <= 0 or N·V <= 0) visible is False and the three angles
are 0 (brightness there is a physical zero, not an error). Floats and a bool for single
vectors, arrays of the leading shape otherwise.)doc");

    m.def(
        "geometry_from_two_azimuths",
        [](py::handle theta_i_deg, py::handle phi_i_deg, py::handle theta_v_deg,
           py::handle phi_v_deg) {
            auto operands = broadcast<4>({"theta_i_deg", "phi_i_deg", "theta_v_deg", "phi_v_deg"},
                                         {theta_i_deg, phi_i_deg, theta_v_deg, phi_v_deg});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> ti = make_output(b), ts = make_output(b), ps = make_output(b);
            double *oi = ti.mutable_data(), *os = ts.mutable_data(), *op = ps.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const auto x = values_at(ops, i);
                const Geometry g = geometry_from_two_azimuths(deg_to_rad(x[0]), deg_to_rad(x[1]),
                                                              deg_to_rad(x[2]), deg_to_rad(x[3]));
                oi[i] = rad_to_deg(g.theta_i_rad);
                os[i] = rad_to_deg(g.theta_s_rad);
                op[i] = rad_to_deg(g.phi_s_rad);
            });
            return py::make_tuple(finish(b, ti), finish(b, ts), finish(b, ps));
        },
        arg("theta_i_deg"), arg("phi_i_deg"), arg("theta_v_deg"), arg("phi_v_deg"),
        R"doc(Geometry in the paper's frame (§2) from a frame that gives both azimuths (e.g.
CUReT's θv, φv, θi, φi): θs = θv, φs = φv − φi + 180 (mod 360).

All angles in degrees; polar angles in [0, 90). Returns (theta_i_deg, theta_s_deg,
phi_s_deg) with phi_s_deg in [0, 360).)doc");

    // ---- Scattering vector, g, F (§3.1–3.2) -------------------------------------------------
    m.def(
        "scattering_vector",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           py::handle wavelength_um) {
            auto operands =
                broadcast<4>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "wavelength_um"},
                             {theta_i_deg, theta_s_deg, phi_s_deg, wavelength_um});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> vx = make_output(b), vy = make_output(b), vz = make_output(b);
            double *ox = vx.mutable_data(), *oy = vy.mutable_data(), *oz = vz.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const auto x = values_at(ops, i);
                const Geometry g = geometry_deg(x[0], x[1], x[2]);
                check_length_um("wavelength_um", x[3]);
                const ScatteringVector v = scattering_vector(g, x[3]);
                ox[i] = v.vx;
                oy[i] = v.vy;
                oz[i] = v.vz;
            });
            return py::make_tuple(finish(b, vx), finish(b, vy), finish(b, vz));
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("wavelength_um") = 0.555,
        R"doc(Scattering vector v = (vx, vy, vz) in 1/µm (§3.1):
vx = k (sin θi − sin θs cos φs), vy = −k sin θs sin φs, vz = −k (cos θi + cos θs),
k = 2π/λ. Angles in degrees, wavelength_um > 0 (default 0.555, the paper's). Returns (vx, vy, vz).)doc");

    m.def(
        "roughness_g",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle sigma_um,
           py::handle wavelength_um) {
            return map_double<4>({"theta_i_deg", "theta_s_deg", "sigma_um", "wavelength_um"},
                                 {theta_i_deg, theta_s_deg, sigma_um, wavelength_um},
                                 [](double ti, double ts, double sigma, double wl) {
                                     const Geometry g = geometry_deg(ti, ts, 0.0);
                                     check::non_negative("sigma_um", sigma, "um");
                                     if (sigma != 0.0) check_length_um("sigma_um", sigma);
                                     check_length_um("wavelength_um", wl);
                                     return roughness_g(g, sigma, wl);
                                 });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("sigma_um"), arg("wavelength_um") = 0.555,
        R"doc(Roughness parameter g = σ² v_z² = (2πσ/λ)² (cos θi + cos θs)² (§3.1); it does not
depend on φs. sigma_um >= 0, wavelength_um > 0 (µm), angles in degrees, in [0, 90).)doc");

    m.def(
        "geometric_factor_squared",
        [](const std::string& factor, py::handle theta_i_deg, py::handle theta_s_deg,
           py::handle phi_s_deg) {
            const GeometricFactor f = parse_geometric_factor(factor);
            return map_double<3>({"theta_i_deg", "theta_s_deg", "phi_s_deg"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg},
                                 [f](double ti, double ts, double ps) {
                                     return geometric_factor_squared(f, geometry_deg(ti, ts, ps));
                                 });
        },
        arg("factor"), arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"),
        R"doc(Squared geometric factor F² of the diffuse term (§3.2):
'beckmann' F_Beck (Eq. 6), 'vh' F_VH² = cos θi (Vernold–Harvey), 'ogilvy' F_Beck cos θi,
'kirchhoff' F_Beck cos θi / cos θs. Angles in degrees.)doc");

    m.def(
        "geometric_factor_beckmann",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg) {
            return map_double<3>({"theta_i_deg", "theta_s_deg", "phi_s_deg"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg},
                                 [](double ti, double ts, double ps) {
                                     return geometric_factor_beckmann(geometry_deg(ti, ts, ps));
                                 });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"),
        R"doc(Beckmann's geometric factor, Eq. 6:
F_Beck = (1 + cos θi cos θs − sin θi sin θs cos φs) / (cos θi (cos θi + cos θs)).
F_Beck(0, 0, ·) = 1; retro (θ, θ, 180): 1/cos²θ. Angles in degrees.)doc");

    m.def(
        "specular_amplitude_rho0",
        [](py::handle vx, py::handle vy, py::handle patch_x_um, py::handle patch_y_um) {
            return map_double<4>({"vx", "vy", "patch_x_um", "patch_y_um"},
                                 {vx, vy, patch_x_um, patch_y_um},
                                 [](double x, double y, double X, double Y) {
                                     check::finite("vx", x);
                                     check::finite("vy", y);
                                     check_length_um("patch_x_um", X);
                                     check_length_um("patch_y_um", Y);
                                     return specular_amplitude_rho0(x, y, X, Y);
                                 });
        },
        arg("vx"), arg("vy"), arg("patch_x_um") = 500.0, arg("patch_y_um") = 500.0,
        R"doc(ρ0 = sinc(vx X) sinc(vy Y) for a 2X × 2Y patch (§3.1); vx, vy in 1/µm, X, Y in µm.
ρ0 = 1 in the specular direction (vx = vy = 0).)doc");

    m.def(
        "coherent_power",
        [](py::handle rho0, py::handle g) {
            return map_double<2>({"rho0", "g"}, {rho0, g}, [](double r, double gg) {
                if (!(r >= -1.0 && r <= 1.0))  // ρ0 is a product of two sincs (§3.1)
                    throw InvalidArgument("rho0 = " + check::format_number(r) +
                                          " is outside the valid range [-1, 1]");
                check::non_negative("g", gg);
                return coherent_power(r, gg);
            });
        },
        arg("rho0"), arg("g"), "Coherent term of Eq. 1: ρ0² exp(−g).");

    // ---- Mean scattered power (Eq. 1–5) ---------------------------------------------------
    m.def(
        "mean_scattered_power",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
           py::handle sigma_um, py::handle T_um, const std::string& correlation,
           const std::string& factor, const std::string& regime, const std::string& radiometry,
           py::handle wavelength_um, py::handle patch_x_um, py::handle patch_y_um,
           py::handle auto_tolerance_in) {
            const double auto_tolerance = real_scalar("auto_tolerance", auto_tolerance_in);
            const Correlation corr = parse_correlation(correlation);
            ModelOptions opt;
            opt.factor = parse_geometric_factor(factor);
            opt.regime = parse_regime(regime);
            opt.radiometry = parse_radiometry(radiometry);
            opt.auto_tolerance = auto_tolerance;
            auto operands = broadcast<8>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "sigma_um",
                                          "T_um", "wavelength_um", "patch_x_um", "patch_y_um"},
                                         {theta_i_deg, theta_s_deg, phi_s_deg, sigma_um, T_um,
                                          wavelength_um, patch_x_um, patch_y_um});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<double> coh = make_output(b), dif = make_output(b), tot = make_output(b),
                                bri = make_output(b), gg = make_output(b), bnd = make_output(b);
            py::array_t<std::uint8_t> reg(b.shape), cls(b.shape), met(b.shape);
            double *oc = coh.mutable_data(), *od = dif.mutable_data(), *ot = tot.mutable_data(),
                   *ob = bri.mutable_data(), *og = gg.mutable_data(), *obd = bnd.mutable_data();
            std::uint8_t *orr = reg.mutable_data(), *ocl = cls.mutable_data(),
                         *om = met.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const auto x = values_at(ops, i);
                ModelOptions o = opt;
                o.wavelength_um = x[5];
                o.patch_x_um = x[6];
                o.patch_y_um = x[7];
                const ScatteredPower p = mean_scattered_power(geometry_deg(x[0], x[1], x[2]),
                                                              Surface{x[3], x[4], corr}, o);
                oc[i] = p.coherent;
                od[i] = p.diffuse;
                ot[i] = p.total;
                ob[i] = p.brightness;
                og[i] = p.g;
                obd[i] = p.relative_error_bound;
                om[i] = static_cast<std::uint8_t>(
                    std::find(kMethods.begin(), kMethods.end(), p.method) - kMethods.begin());
                orr[i] = static_cast<std::uint8_t>(
                    std::find(kRegimes.begin(), kRegimes.end(), p.regime) - kRegimes.begin());
                ocl[i] = static_cast<std::uint8_t>(std::find(kRoughnessClasses.begin(),
                                                             kRoughnessClasses.end(),
                                                             p.roughness_class) -
                                                   kRoughnessClasses.begin());
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
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("sigma_um"), arg("T_um"),
        py::kw_only(), arg("correlation") = "gaussian", arg("factor") = "vh",
        arg("regime") = "auto", arg("radiometry") = "radiance", arg("wavelength_um") = 0.555,
        arg("patch_x_um") = 500.0, arg("patch_y_um") = 500.0, arg("auto_tolerance") = 1e-12,
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

    // ---- Retro-scattering closed forms (Eq. 7–11) -----------------------------------------
    auto retro_vr = [&m](const char* name, double (*fn)(double, double), const char* doc) {
        m.def(
            name,
            [fn](py::handle theta_deg, py::handle sigma_over_T) {
                return map_double<2>({"theta_deg", "sigma_over_T"}, {theta_deg, sigma_over_T},
                                     [fn](double t, double r) { return fn(deg_to_rad(t), r); });
            },
            py::arg("theta_deg"), py::arg("sigma_over_T"), doc);
    };
    retro_vr("retro_beckmann_gaussian_very_rough", &retro_beckmann_gaussian_very_rough,
             "Eq. 7 (original B–K, Gaussian correlation, very rough, retro θi = θs = θ, φs = "
             "180): exp(−T² tan²θ/(4σ²)) / cos⁶θ. theta_deg in [0, 90), sigma_over_T > 0.");
    retro_vr("retro_beckmann_exponential_very_rough", &retro_beckmann_exponential_very_rough,
             "Eq. 8 (original B–K, exponential correlation): 1 / (cos⁶θ [1 + (T/σ)² "
             "tan²θ]^{3/2}). theta_deg in [0, 90), sigma_over_T > 0.");
    retro_vr("retro_vh_gaussian_very_rough", &retro_vh_gaussian_very_rough,
             "Eq. 9 (V–H modified B–K, Gaussian correlation): exp(−T² tan²θ/(4σ²)) / cos θ. "
             "theta_deg in [0, 90), sigma_over_T > 0.");
    retro_vr("retro_vh_exponential_very_rough", &retro_vh_exponential_very_rough,
             "Eq. 10 (V–H modified B–K, exponential correlation): 1 / (cos θ [1 + (T/σ)² "
             "tan²θ]^{3/2}). theta_deg in [0, 90), sigma_over_T > 0.");
    m.def(
        "retro_vh_gaussian_slightly_rough",
        [](py::handle theta_deg, py::handle sigma_um, py::handle T_um, py::handle wavelength_um) {
            return map_double<4>({"theta_deg", "sigma_um", "T_um", "wavelength_um"},
                                 {theta_deg, sigma_um, T_um, wavelength_um},
                                 [](double t, double s, double T, double wl) {
                                     return retro_vh_gaussian_slightly_rough(deg_to_rad(t), s, T,
                                                                             wl);
                                 });
        },
        arg("theta_deg"), arg("sigma_um"), arg("T_um"), arg("wavelength_um") = 0.555,
        R"doc(Eq. 11 (V–H, Gaussian correlation, slightly rough, retro):
cos³θ exp(−k² ([T sin θ]² + [2σ cos θ]²)), k = 2π/λ. Lengths in µm.)doc");

    // ---- Validity (§3.1, §3.5) ------------------------------------------------------------
    m.def(
        "roughness_class",
        [](py::handle g) {
            auto operands = broadcast<1>({"g"}, {g});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<std::uint8_t> codes(b.shape);
            std::uint8_t* oc = codes.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const double gg = ops[0].data[i * ops[0].step];
                check::non_negative("g", gg);
                oc[i] = static_cast<std::uint8_t>(std::find(kRoughnessClasses.begin(),
                                                            kRoughnessClasses.end(),
                                                            roughness_class(gg)) -
                                                  kRoughnessClasses.begin());
            });
            return names_from_codes(b, codes, enum_names(kRoughnessClasses));
        },
        arg("g"),
        R"doc(Roughness class by g (§3.1): 'slightly_rough' for g < 0.1, 'very_rough' for g > 10,
'moderately_rough' otherwise. A str for scalar g, else a NumPy str array.)doc");

    m.def(
        "rms_slope",
        [](py::handle sigma_over_T) {
            return map_double<1>({"sigma_over_T"}, {sigma_over_T}, [](double r) {
                check::non_negative("sigma_over_T", r);
                return rms_slope(r);
            });
        },
        arg("sigma_over_T"), "RMS slope m = σ√2/T (§4; Gaussian correlation). sigma_over_T >= 0.");
    m.def(
        "caron_theta_K_deg",
        [](py::handle sigma_over_T) {
            return map_double<1>({"sigma_over_T"}, {sigma_over_T}, [](double r) {
                check::non_negative("sigma_over_T", r);
                return rad_to_deg(caron_theta_K_rad(r));
            });
        },
        arg("sigma_over_T"),
        "Caron's angle of RMS slope θK = 90° − atan(σ√2/T) in degrees (§3.5): incidence "
        "angles above it are outside the model's validity. sigma_over_T >= 0.");
    m.def(
        "caron_xi_K",
        [](py::handle sigma_over_T) {
            return map_double<1>({"sigma_over_T"}, {sigma_over_T}, [](double r) {
                check::non_negative("sigma_over_T", r);
                return caron_xi_K(r);
            });
        },
        arg("sigma_over_T"),
        "Caron's energy conservation rate at normal incidence, g >> 1: ξK = 1 − exp(−T²/(4σ²)) "
        "(§3.5). sigma_over_T >= 0.");

    // ---- Comparison models (§5) -----------------------------------------------------------
    m.def(
        "lambert_brightness",
        [](py::handle theta_i_deg) {
            return map_double<1>({"theta_i_deg"}, {theta_i_deg},
                                 [](double t) { return lambert_brightness(deg_to_rad(t)); });
        },
        arg("theta_i_deg"), "Lambert's cosine law: cos θi (θi in degrees, [0, 90)).");

    auto oren_nayar_like = [&m](const char* name, auto fn, const char* doc) {
        m.def(
            name,
            [fn](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
                 py::handle sigma_rad, py::handle albedo) {
                return map_double<5>(
                    {"theta_i_deg", "theta_s_deg", "phi_s_deg", "sigma_rad", "albedo"},
                    {theta_i_deg, theta_s_deg, phi_s_deg, sigma_rad, albedo},
                    [fn](double ti, double ts, double ps, double s, double a) {
                        return fn(geometry_deg(ti, ts, ps), OrenNayarParams{s, a});
                    });
            },
            py::arg("theta_i_deg"), py::arg("theta_s_deg"), py::arg("phi_s_deg"),
            py::arg("sigma_rad"), py::arg("albedo") = 1.0, doc);
    };
    oren_nayar_like(
        "oren_nayar_radiance",
        [](const Geometry& g, const OrenNayarParams& p) { return oren_nayar_radiance(g, p); },
        "Full Oren–Nayar model (1994) with the inter-reflection term, radiance for unit "
        "irradiance. sigma_rad: standard deviation of the facet slope angle in radians (>= 0; "
        "not the height σ); albedo in [0, 1]. σ = 0 gives (ρ/π) cos θi. Angles in degrees.");
    oren_nayar_like(
        "oren_nayar_qualitative_radiance",
        [](const Geometry& g, const OrenNayarParams& p) {
            return oren_nayar_qualitative_radiance(g, p);
        },
        "Qualitative Oren–Nayar model: (ρ/π) cos θi [A + B max(0, cos(φr − φi)) "
        "sin α tan β]. sigma_rad in radians, albedo in [0, 1]; angles in degrees.");

    m.def(
        "lafortune_diffuse_brightness",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg, py::handle n) {
            return map_double<4>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "n"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg, n},
                                 [](double ti, double ts, double ps, double nn) {
                                     return lafortune_diffuse_brightness(geometry_deg(ti, ts, ps),
                                                                         nn);
                                 });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("n"),
        "Lafortune diffuse lobe (Cx = Cy = 0, Cz = 1) as the paper fits it to CUReT: brightness "
        "(cos θi cos θs)^n cos θi. Angles in degrees; n > 0.");

    m.def(
        "lafortune_brdf",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg, py::handle lobes,
           py::handle rho_d_in) {
            const double rho_d = real_scalar("rho_d", rho_d_in);
            const std::vector<LafortuneLobe> lobe_list = lobes_from_python(lobes);
            return map_double<3>(
                {"theta_i_deg", "theta_s_deg", "phi_s_deg"}, {theta_i_deg, theta_s_deg, phi_s_deg},
                [&lobe_list, rho_d](double ti, double ts, double ps) {
                    return lafortune_brdf(geometry_deg(ti, ts, ps), lobe_list, rho_d);
                });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("lobes"), arg("rho_d") = 0.0,
        R"doc(Lafortune et al. (1997) BRDF: rho_d/π + Σ_lobes albedo [Cx Lx Vx + Cy Ly Vy + Cz Lz Vz]^n
(a lobe is 0 where its bracket is <= 0). lobes: a list of dicts with keys Cx, Cy, Cz, n, albedo
(missing keys: Cx = Cy = 0, Cz = 1, n = 1, albedo = 1), or an array of shape (N, 5) with those
columns. Angles in degrees; rho_d >= 0.)doc");
}

}  // namespace roughscope::python
