// The single entry point of roughscope_bench. Each other bench/*.cpp file only
// registers benchmarks (BENCHMARK(...)); run with --help for the options.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
