// I/O benchmarks: the per-row cost of the streaming `roughscope model --csv` path (read a CSV
// row, evaluate the B–K model of Eq. 1–5, format the record, write it through io::OutputFile)
// against the pure computation of the same rows, timed in the same run.
//
//   build*/bin/roughscope_bench --benchmark_filter='io/'
//
// Names: io/model_compute/<rows>      mean_scattered_power at the rows' geometries (the baseline)
//        io/model_csv/<format>/<rows> the CLI's `model --csv FILE --sigma 1 --T 2 [--json]
//                                     --output FILE` run in-process on the same rows; counters:
//                                     ns_per_row, and time_vs_compute = its fastest run over the
//                                     baseline's fastest, both timed in every iteration (processor
//                                     time)
//        io/csv_read/<rows>           io::CsvReader alone over the same file (parsing only)
//        io/curet_compute/<rows>      compare_brdf on the same geometries as an in-memory BRDF
//                                     table (the baseline; predictions not kept)
//        io/curet_table/<rows>        the CLI's `curet --table FILE --json --output FILE` on that
//                                     table written as CSV; counters as for io/model_csv
// The rows cover θi, θs in [0, 80) degrees and φs in [0, 360) (σ = 1 µm, T = 2 µm, λ = 0.555 µm).
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/table.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"

#ifdef ROUGHSCOPE_BENCH_HAS_CLI
#include <CLI/CLI.hpp>

#include "commands.hpp"
#endif

namespace {

using namespace roughscope;
namespace fs = std::filesystem;

constexpr std::size_t kRows = 20000;

// The benchmark's input: a CSV file of kRows geometries (degrees) and the same geometries parsed.
struct Rows {
    fs::path dir, csv, output, brdf_csv;
    std::vector<Geometry> geometries;
    BrdfTable table;  // the same geometries with a BRDF value (curet --table)
};

const Rows& rows() {
    static const Rows r = [] {
        Rows out;
        out.dir = fs::temp_directory_path() / "roughscope_bench_io";
        fs::create_directories(out.dir);
        out.csv = out.dir / "rows.csv";
        out.output = out.dir / "out.txt";
        out.brdf_csv = out.dir / "brdf.csv";
        std::ofstream f(out.csv, std::ios::binary);
        std::ofstream b(out.brdf_csv, std::ios::binary);
        f << "theta_i,theta_s,phi_s\n";
        b << "theta_i,phi_i,theta_s,phi_s,value\n";
        for (std::size_t k = 0; k < kRows; ++k) {
            const double ti = static_cast<double>(k * 7 % 800) / 10.0;
            const double ts = static_cast<double>(k * 13 % 800) / 10.0;
            const double ps = static_cast<double>(k * 17 % 3600) / 10.0;
            f << ti << ',' << ts << ',' << ps << '\n';
            b << ti << ",180," << ts << ',' << ps << ',' << 0.5 + static_cast<double>(k % 97) / 100
              << '\n';
            out.geometries.push_back(make_geometry(deg_to_rad(ti), deg_to_rad(ts), deg_to_rad(ps)));
        }
        b.close();
        out.table = read_brdf_csv(out.brdf_csv);
        return out;
    }();
    return r;
}

ModelOptions model_options() {
    ModelOptions o;
    o.wavelength_um = 0.555;
    return o;
}

double compute_all(const std::vector<Geometry>& geometries) {
    const Surface surface{1.0, 2.0, Correlation::Gaussian};
    const ModelOptions options = model_options();
    double sum = 0.0;
    for (const Geometry& g : geometries) sum += mean_scattered_power(g, surface, options).total;
    return sum;
}

void BM_model_compute(benchmark::State& state) {
    const Rows& r = rows();
    for (auto _ : state) benchmark::DoNotOptimize(compute_all(r.geometries));
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kRows));
    state.counters["ns_per_row"] = benchmark::Counter(
        static_cast<double>(kRows) * 1e-9,
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_model_compute)->Name("io/model_compute/20000")->Unit(benchmark::kMillisecond);

void BM_csv_read(benchmark::State& state) {
    const Rows& r = rows();
    for (auto _ : state) {
        io::CsvReader reader(r.csv, {"theta_i", "theta_s", "phi_s"},
                             {"sigma_um", "T_um", "sigma_over_T"});
        io::CsvRow row;
        double sum = 0.0;
        while (reader.next(row)) sum += *row.value(0);
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kRows));
}
BENCHMARK(BM_csv_read)->Name("io/csv_read/20000")->Unit(benchmark::kMillisecond);

ComparisonOptions curet_options() {
    ComparisonOptions o;
    o.keep_predictions = false;  // as the CLI without --series
    return o;
}

void BM_curet_compute(benchmark::State& state) {
    const Rows& r = rows();
    for (auto _ : state) benchmark::DoNotOptimize(compare_brdf(r.table, curet_options()));
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kRows));
}
BENCHMARK(BM_curet_compute)->Name("io/curet_compute/20000")->Unit(benchmark::kMillisecond);

#ifdef ROUGHSCOPE_BENCH_HAS_CLI
// Runs `roughscope model --csv ... --output ...` in-process through the CLI's own code.
void run_cli_model(const Rows& r, bool json) {
    CLI::App app{"bench", "roughscope"};
    cli::register_model(app);
    std::vector<std::string> args = {
        "roughscope", "model", "--csv", r.csv.string(), "--sigma",
        "1",          "--T",   "2",     "--output",     r.output.string()};
    if (json) args.emplace_back("--json");
    std::vector<char*> argv;
    argv.reserve(args.size());
    for (std::string& a : args) argv.push_back(a.data());
    app.parse(static_cast<int>(argv.size()), argv.data());
}

// Processor time of this process in seconds (both sides are single-threaded: the ratio does not
// depend on what else the machine runs).
double cpu_seconds() {
    timespec t{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Each iteration times the computation and then the command on the same rows (processor time,
// both single-threaded); the ratio is fastest command over fastest computation, so a slow moment
// of the machine moves neither side alone.
template <class Compute, class Command>
void time_against_compute(benchmark::State& state, Compute&& compute, Command&& command) {
    double best_compute = 1e300, best_command = 1e300;
    for (auto _ : state) {
        const double t0 = cpu_seconds();
        compute();
        const double t1 = cpu_seconds();
        command();
        const double t2 = cpu_seconds();
        best_compute = std::min(best_compute, t1 - t0);
        best_command = std::min(best_command, t2 - t1);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kRows));
    state.counters["ns_per_row"] = best_command / static_cast<double>(kRows) * 1e9;
    state.counters["compute_ns_per_row"] = best_compute / static_cast<double>(kRows) * 1e9;
    state.counters["time_vs_compute"] = best_command / best_compute;
}

void BM_model_csv(benchmark::State& state, bool json) {
    const Rows& r = rows();
    time_against_compute(
        state, [&] { benchmark::DoNotOptimize(compute_all(r.geometries)); },
        [&] { run_cli_model(r, json); });
}
BENCHMARK_CAPTURE(BM_model_csv, csv, false)
    ->Name("io/model_csv/csv/20000")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_model_csv, json, true)
    ->Name("io/model_csv/json/20000")
    ->Unit(benchmark::kMillisecond);

// `roughscope curet --table FILE --json --output FILE` in-process, against compare_brdf on the
// table already in memory (processor time, as above).
void BM_curet_table(benchmark::State& state) {
    const Rows& r = rows();
    time_against_compute(
        state, [&] { benchmark::DoNotOptimize(compare_brdf(r.table, curet_options())); },
        [&] {
            CLI::App app{"bench", "roughscope"};
            cli::register_curet(app);
            std::vector<std::string> args = {"roughscope",        "curet",  "--table",
                                             r.brdf_csv.string(), "--json", "--output",
                                             r.output.string()};
            std::vector<char*> argv;
            argv.reserve(args.size());
            for (std::string& a : args) argv.push_back(a.data());
            app.parse(static_cast<int>(argv.size()), argv.data());
        });
}
BENCHMARK(BM_curet_table)->Name("io/curet_table/20000")->Unit(benchmark::kMillisecond);
#endif

}  // namespace
