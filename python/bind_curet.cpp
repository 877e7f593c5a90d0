// Bindings for measured BRDFs (CUReT and any BRDF table) and the model comparison of §5.3.
// Angles cross this boundary in degrees. Comparisons are returned as dicts built by the library's
// serializer (roughscope/serialize/comparison.hpp): the document of `roughscope curet --json`
// as Python objects. The options become a ComparisonOptions in one place,
// serialize::comparison_options_from, which the CLI calls too.
#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/brdf/table.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/serialize/comparison.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

// compare_all(format=...): names in the library's enum-name scheme (roughscope/core/names.hpp),
// case-insensitive, as the CLI's --format.
enum class AllFormat { Dict, Csv, Markdown };
constexpr std::array<NameEntry<AllFormat>, 4> kAllFormatNames{{
    {"dict", AllFormat::Dict},
    {"csv", AllFormat::Csv},
    {"markdown", AllFormat::Markdown},
    {"md", AllFormat::Markdown},  // alias, as for the CLI
}};

py::array_t<double> vector_array(const std::vector<double>& v) {
    return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::array_t<double> matrix_array(const std::vector<std::vector<double>>& rows) {
    const py::ssize_t n = static_cast<py::ssize_t>(rows.size());
    const py::ssize_t m = n ? static_cast<py::ssize_t>(rows[0].size()) : 0;
    py::array_t<double> out({n, m});
    auto r = out.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i)
        for (py::ssize_t j = 0; j < m; ++j)
            r(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
    return out;
}

// Named comparison options (None = default) → ComparisonOptions, by the library.
ComparisonOptions make_options(py::object theta1_deg, py::object theta2_deg, py::object pair,
                               py::object on_sigma_rad, py::object on_albedo, bool fits,
                               const std::string& radiometry, py::object max_overflow) {
    using namespace py::literals;
    // Numeric options are checked here (TypeError for a non-real value, bindings.hpp).
    py::object pair_checked = pair;
    if (!pair.is_none()) {
        py::list items;
        if (py::isinstance<py::str>(pair) || py::isinstance<py::bytes>(pair) ||
            !py::hasattr(pair, "__iter__"))
            throw py::type_error("pair must be two measurement numbers (I, J), not " +
                                 py::str(py::type::of(pair).attr("__name__")).cast<std::string>());
        for (py::handle item : py::iter(pair)) items.append(integer_scalar("pair", item));
        pair_checked = items;
    }
    const py::dict o(
        "theta1_deg"_a = real_option("theta1_deg", theta1_deg),
        "theta2_deg"_a = real_option("theta2_deg", theta2_deg), "pair"_a = pair_checked,
        "on_sigma_rad"_a = real_option("on_sigma_rad", on_sigma_rad),
        "on_albedo"_a = real_option("on_albedo", on_albedo), "fits"_a = fits,
        "radiometry"_a = radiometry, "max_overflow"_a = real_option("max_overflow", max_overflow));
    return serialize::comparison_options_from(from_python(o, "comparison option"));
}

py::dict table_dict(const BrdfTable& t) {
    std::vector<double> idx, ti, pi, tv, pv, f, w, ts, ps;
    for (const BrdfMeasurement& m : t.measurements) {
        idx.push_back(m.index);
        ti.push_back(rad_to_deg(m.theta_i_rad));
        pi.push_back(rad_to_deg(m.phi_i_rad));
        tv.push_back(rad_to_deg(m.theta_v_rad));
        pv.push_back(rad_to_deg(m.phi_v_rad));
        f.push_back(m.value);
        w.push_back(m.weight);
        ts.push_back(rad_to_deg(m.geometry.theta_s_rad));
        ps.push_back(rad_to_deg(m.geometry.phi_s_rad));
    }
    py::dict d;
    d["name"] = t.name;
    d["channel"] = t.channel;
    d["measurement"] = vector_array(idx).attr("astype")("int64");
    d["theta_i_deg"] = vector_array(ti);
    d["phi_i_deg"] = vector_array(pi);
    d["theta_v_deg"] = vector_array(tv);
    d["phi_v_deg"] = vector_array(pv);
    d["value"] = vector_array(f);
    d["weight"] = vector_array(w);
    d["theta_s_deg"] = vector_array(ts);  // paper's frame
    d["phi_s_deg"] = vector_array(ps);
    return d;
}

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A sample number: an integer (TypeError otherwise); values beyond int are clamped to one that no
// sample has, so the library reports them as unknown.
int sample_number(py::handle sample) {
    return static_cast<int>(std::clamp<long long>(integer_scalar("sample", sample), -1, 1000000));
}

// A numeric array argument: TypeError for a non-real type (real_array, bindings.hpp).
DoubleArray real_double_array(const char* name, py::handle value) {
    DoubleArray a = DoubleArray::ensure(real_array(name, value));
    if (!a) throw py::error_already_set();
    return a;
}

BrdfTable table_from_arrays(const DoubleArray& ti, const DoubleArray& pi, const DoubleArray& ts,
                            const DoubleArray& ps, const DoubleArray& value,
                            const std::optional<DoubleArray>& weight, const std::string& name) {
    const py::ssize_t n = value.size();
    for (auto [label, arr] : {std::pair{"theta_i_deg", &ti}, std::pair{"phi_i_deg", &pi},
                              std::pair{"theta_s_deg", &ts}, std::pair{"phi_s_deg", &ps}})
        if (arr->ndim() != 1 || arr->size() != n)
            throw InvalidArgument(std::string(label) + " must be a 1-D array as long as value (" +
                                  std::to_string(n) + "), got size " + std::to_string(arr->size()));
    if (value.ndim() != 1) throw InvalidArgument("value must be a 1-D array");
    if (weight && (weight->ndim() != 1 || weight->size() != n))
        throw InvalidArgument("weight must be a 1-D array as long as value (" + std::to_string(n) +
                              ")");
    BrdfTable t;
    t.name = name;
    for (py::ssize_t j = 0; j < n; ++j)
        t.measurements.push_back(make_brdf_measurement(
            static_cast<int>(j + 1), deg_to_rad(ti.at(j)), deg_to_rad(pi.at(j)),
            deg_to_rad(ts.at(j)), deg_to_rad(ps.at(j)), value.at(j), weight ? weight->at(j) : 1.0));
    return t;
}

// The database's contents as read-only properties: directory, channel, samples, brdf, overflow
// and the angles in both frames.
void add_curet_contents(py::class_<CuretDatabase>& database) {
    database
        .def_property_readonly("directory",
                               [](const CuretDatabase& db) { return db.directory.string(); })
        .def_property_readonly(
            "channel", [](const CuretDatabase& db) { return std::string(to_string(db.channel)); })
        .def_property_readonly(
            "samples",
            [](const CuretDatabase& db) {
                py::array_t<long long> out(static_cast<py::ssize_t>(db.samples.size()));
                for (std::size_t k = 0; k < db.samples.size(); ++k)
                    out.mutable_at(static_cast<py::ssize_t>(k)) = db.samples[k];
                return out;
            },
            "Sample numbers in file order (int64, shape (61,))")
        .def_property_readonly(
            "brdf", [](const CuretDatabase& db) { return matrix_array(db.brdf); },
            "BRDF values f in 1/sr, shape (samples, 205); row k is samples[k], column j is "
            "measurement j+1. Non-positive values (noise) are kept.")
        .def_property_readonly(
            "overflow",
            [](const CuretDatabase& db) -> py::object {
                if (db.overflow.empty()) return py::none();
                return matrix_array(db.overflow);
            },
            "Saturated-pixel fractions (same shape as brdf) or None when not published")
        .def_property_readonly(
            "angles_deg",
            [](const CuretDatabase& db) {
                std::vector<double> meas, tv, pv, ti, pi, ts, ps;
                for (const CuretAngles& a : db.angles) {
                    meas.push_back(a.measurement);
                    tv.push_back(rad_to_deg(a.theta_v_rad));
                    pv.push_back(rad_to_deg(a.phi_v_rad));
                    ti.push_back(rad_to_deg(a.theta_i_rad));
                    pi.push_back(rad_to_deg(a.phi_i_rad));
                    const Geometry g = geometry_from_two_azimuths(a.theta_i_rad, a.phi_i_rad,
                                                                  a.theta_v_rad, a.phi_v_rad);
                    ts.push_back(rad_to_deg(g.theta_s_rad));
                    ps.push_back(rad_to_deg(g.phi_s_rad));
                }
                py::dict d;
                d["measurement"] = vector_array(meas).attr("astype")("int64");
                d["theta_v_deg"] = vector_array(tv);
                d["phi_v_deg"] = vector_array(pv);
                d["theta_i_deg"] = vector_array(ti);
                d["phi_i_deg"] = vector_array(pi);
                d["theta_s_deg"] = vector_array(ts);
                d["phi_s_deg"] = vector_array(ps);
                return d;
            },
            "table.txt in degrees (sample frame) plus theta_s_deg, phi_s_deg in the paper's frame "
            "(theta_s = theta_v, phi_s = phi_v - phi_i + 180)");
}

// One sample's table and the model comparisons of one sample or of all of them.
void add_curet_comparisons(py::class_<CuretDatabase>& database) {
    database
        .def(
            "sample_table",
            [](const CuretDatabase& db, py::handle sample) {
                return table_dict(db.sample_table(sample_number(sample)));
            },
            py::arg("sample"), "One sample's measurements as a dict of numpy arrays (degrees)")
        .def(
            "compare",
            [](const CuretDatabase& db, py::handle sample_in, py::object theta1_deg,
               py::object theta2_deg, py::object pair, py::object on_sigma_rad,
               py::object on_albedo, bool fits, const std::string& radiometry,
               py::object max_overflow, bool series) {
                const int sample = sample_number(sample_in);
                const ComparisonOptions o = make_options(theta1_deg, theta2_deg, pair, on_sigma_rad,
                                                         on_albedo, fits, radiometry, max_overflow);
                serialize::Json doc;
                {
                    py::gil_scoped_release release;
                    doc = serialize::to_json(compare_curet_sample(db, sample, o), series);
                }
                return to_python(doc);
            },
            py::arg("sample"), py::kw_only(), py::arg("theta1_deg") = py::none(),
            py::arg("theta2_deg") = py::none(), py::arg("pair") = py::none(),
            py::arg("on_sigma_rad") = py::none(), py::arg("on_albedo") = py::none(),
            py::arg("fits") = true, py::arg("radiometry") = "radiance",
            py::arg("max_overflow") = py::none(), py::arg("series") = true,
            "Compare every model with one sample: a dict (see roughscope.curet.compare)")
        .def(
            "compare_all",
            [](const CuretDatabase& db, bool fits, const std::string& radiometry,
               py::object max_overflow, py::handle threads_in, const std::string& format,
               bool series) -> py::object {
                const long long threads_ll = integer_scalar("threads", threads_in);
                if (threads_ll < 0 || threads_ll > 1024)
                    throw InvalidArgument("threads = " + std::to_string(threads_ll) +
                                          " is outside the valid range [0, 1024]");
                const int threads = static_cast<int>(threads_ll);
                const ComparisonOptions o =
                    make_options(py::none(), py::none(), py::none(), py::none(), py::none(), fits,
                                 radiometry, max_overflow);
                const AllFormat f = parse_name(kAllFormatNames, "format", format);
                std::vector<Comparison> all;
                {
                    py::gil_scoped_release release;
                    all = compare_curet_all(db, o, threads);
                }
                switch (f) {
                    case AllFormat::Csv:
                        return py::str(serialize::to_csv(all));
                    case AllFormat::Markdown:
                        return py::str(serialize::to_markdown(all));
                    case AllFormat::Dict:
                        break;
                }
                return to_python(serialize::to_json(all, series));
            },
            py::kw_only(), py::arg("fits") = true, py::arg("radiometry") = "radiance",
            py::arg("max_overflow") = py::none(), py::arg("threads") = 0,
            py::arg("format") = "dict", py::arg("series") = false,
            "Compare every sample: a list of dicts (format='dict'), or CSV or Markdown text");
}

}  // namespace

void bind_curet_database(py::module_& m) {
    py::class_<CuretDatabase> database(
        m, "CuretDatabase", "The CUReT BRDF database for one channel (load with curet_load).");
    add_curet_contents(database);
    add_curet_comparisons(database);

    m.def(
        "curet_find_directory",
        [](std::optional<std::string> data_dir) {
            return find_curet_directory(data_dir ? std::optional<std::filesystem::path>(
                                                       path_argument("data_dir", *data_dir))
                                                 : std::nullopt)
                .string();
        },
        py::arg("data_dir") = py::none(),
        "The CUReT directory: data_dir, else $ROUGHSCOPE_SHARED_DIR/data/curet, else "
        "../shared/data/curet searched upward from the current directory, else $ROUGHSCOPE_CURET "
        "(DataError saying where to get the database otherwise)");
    m.def(
        "curet_load",
        [](std::optional<std::string> data_dir, const std::string& channel) {
            const auto dir = find_curet_directory(
                data_dir
                    ? std::optional<std::filesystem::path>(path_argument("data_dir", *data_dir))
                    : std::nullopt);
            return load_curet(dir, parse_curet_channel(channel));
        },
        py::arg("data_dir") = py::none(), py::arg("channel") = "mean",
        "Load the CUReT database (channel: mean, red, green, blue)");
    m.def(
        "curet_sample_name",
        [](py::handle sample) { return std::string(curet_sample_name(sample_number(sample))); },
        py::arg("sample"), "The paper's name for samples 25, 34, 41; '' otherwise");
    m.def(
        "curet_paper_oren_nayar",
        [](py::handle sample) -> py::object {
            const auto p = paper_oren_nayar_params(sample_number(sample));
            if (!p) return py::none();
            return py::make_tuple(p->sigma_rad, p->albedo);
        },
        py::arg("sample"), "(sigma_rad, albedo) of the paper's Table 3, or None");
}

void bind_brdf_tables(py::module_& m) {
    m.def(
        "brdf_read_csv",
        [](const std::string& path, std::optional<std::string> channel) {
            BrdfCsvOptions o;
            o.channel = channel;
            return table_dict(read_brdf_csv(path_argument("path", path), o));
        },
        py::arg("path"), py::arg("channel") = py::none(),
        "Read a BRDF table (CSV: theta_i, phi_i, theta_s, phi_s in degrees, value; optional "
        "weight, channel, measurement) into a dict of numpy arrays");
    m.def(
        "brdf_compare_csv",
        [](const std::string& path, std::optional<std::string> channel, py::object theta1_deg,
           py::object theta2_deg, py::object pair, py::object on_sigma_rad, py::object on_albedo,
           bool fits, const std::string& radiometry, bool series) {
            BrdfCsvOptions co;
            co.channel = channel;
            const ComparisonOptions o = make_options(theta1_deg, theta2_deg, pair, on_sigma_rad,
                                                     on_albedo, fits, radiometry, py::none());
            return to_python(serialize::to_json(
                compare_brdf(read_brdf_csv(path_argument("path", path), co), o), series));
        },
        py::arg("path"), py::kw_only(), py::arg("channel") = py::none(),
        py::arg("theta1_deg") = py::none(), py::arg("theta2_deg") = py::none(),
        py::arg("pair") = py::none(), py::arg("on_sigma_rad") = py::none(),
        py::arg("on_albedo") = py::none(), py::arg("fits") = true,
        py::arg("radiometry") = "radiance", py::arg("series") = true,
        "Compare every model with a BRDF table read from CSV (a dict)");
    m.def(
        "brdf_compare_arrays",
        [](py::handle theta_i_deg, py::handle phi_i_deg, py::handle theta_s_deg,
           py::handle phi_s_deg, py::handle value, py::handle weight, const std::string& name,
           py::object theta1_deg, py::object theta2_deg, py::object pair, py::object on_sigma_rad,
           py::object on_albedo, bool fits, const std::string& radiometry, bool series) {
            std::optional<DoubleArray> w;
            if (!weight.is_none()) w = real_double_array("weight", weight);
            const BrdfTable t = table_from_arrays(real_double_array("theta_i_deg", theta_i_deg),
                                                  real_double_array("phi_i_deg", phi_i_deg),
                                                  real_double_array("theta_s_deg", theta_s_deg),
                                                  real_double_array("phi_s_deg", phi_s_deg),
                                                  real_double_array("value", value), w, name);
            const ComparisonOptions o = make_options(theta1_deg, theta2_deg, pair, on_sigma_rad,
                                                     on_albedo, fits, radiometry, py::none());
            return to_python(serialize::to_json(compare_brdf(t, o), series));
        },
        py::arg("theta_i_deg"), py::arg("phi_i_deg"), py::arg("theta_s_deg"), py::arg("phi_s_deg"),
        py::arg("value"), py::kw_only(), py::arg("weight") = py::none(), py::arg("name") = "table",
        py::arg("theta1_deg") = py::none(), py::arg("theta2_deg") = py::none(),
        py::arg("pair") = py::none(), py::arg("on_sigma_rad") = py::none(),
        py::arg("on_albedo") = py::none(), py::arg("fits") = true,
        py::arg("radiometry") = "radiance", py::arg("series") = true,
        "Compare every model with a BRDF table given as arrays (degrees; measurement j+1 is "
        "element j). A dict.");
    m.def(
        "comparison_error_measures",
        [](py::handle model, py::handle data, py::handle weights) {
            auto vector_of = [](const char* name, py::handle h) {
                const DoubleArray a = real_double_array(name, h);
                if (a.ndim() != 1)
                    throw InvalidArgument(std::string(name) + " must be a 1-d sequence of numbers");
                return std::vector<double>(a.data(), a.data() + a.size());
            };
            const std::vector<double> M = vector_of("model", model), D = vector_of("data", data);
            std::optional<std::vector<double>> wv;
            if (!weights.is_none()) wv = vector_of("weights", weights);
            const ErrorMeasures e =
                error_measures(M, D, wv ? std::span<const double>(*wv) : std::span<const double>());
            py::dict d;
            d["sse"] = e.paper_sse;
            d["rmse"] = e.rmse;
            d["sse_gain"] = e.gain_sse;
            d["gain"] = e.gain;
            return d;
        },
        py::arg("model"), py::arg("data"), py::arg("weights") = py::none(),
        "The paper's Table-4 error (sum of (M/max M - d/max d)^2), RMSE and the SSE after the "
        "optimal gain");
}

}  // namespace roughscope::python
