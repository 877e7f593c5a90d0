# roughscope — the two README commands (`make demo`, `make test`) and helpers.
# Every target that builds first installs the Debian dependencies
# (scripts/install-deps; a quick no-op once they are there).

BUILD      ?= build
# One clang build with AddressSanitizer + UBSan and libFuzzer's coverage instrumentation serves
# both `make sanitize` (the C++ and CLI tests) and `make fuzz` (the fuzz targets): the library is
# compiled once for both.
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= $(ASAN_BUILD)
FUZZ_SECONDS ?= 30
JOBS       ?= 2
PYTHON     ?= /usr/bin/python3
CMAKE      ?= cmake
CTEST      ?= ctest
REPORT_DIR ?= out/report
# Warnings as errors: ON in CI (.ci/run exports ROUGHSCOPE_WERROR=ON), OFF by default.
ROUGHSCOPE_WERROR ?= OFF

# ccache (installed by scripts/install-deps) makes rebuilds of unchanged sources cheap, also from
# another clone on the same machine (paths are taken relative to the clone). It is looked up by
# the shell when each configure step runs — after scripts/install-deps — so that the very first
# build on a fresh machine already goes through it (a lookup when make reads this file would
# find nothing there, and the next configure would then rebuild everything).
export CCACHE_BASEDIR ?= $(CURDIR)
# The sanitizer and fuzz builds have debug info (-g), for which ccache by default also hashes the
# working directory: without this, another clone (CI's) would rebuild them cold.
export CCACHE_NOHASHDIR ?= 1
LAUNCHER_FLAGS = $$(command -v ccache >/dev/null 2>&1 && echo -DCMAKE_CXX_COMPILER_LAUNCHER=$$(command -v ccache))

CONFIGURE_FLAGS = -G Ninja $(LAUNCHER_FLAGS) \
	-DCMAKE_BUILD_TYPE=Release \
	-DROUGHSCOPE_BUILD_TESTS=ON \
	-DROUGHSCOPE_BUILD_PYTHON=ON \
	-DROUGHSCOPE_BUILD_BENCH=ON \
	-DROUGHSCOPE_BUILD_CLI=ON \
	-DROUGHSCOPE_SANITIZE=OFF \
	-DROUGHSCOPE_WERROR=$(ROUGHSCOPE_WERROR) \
	-DPython3_EXECUTABLE=$(PYTHON)

# The sanitizer build (clang): every object instrumented with ASan + UBSan and libFuzzer's
# coverage (-fsanitize=fuzzer-no-link: ROUGHSCOPE_BUILD_FUZZERS), asserts on; the tests, the CLI
# and the libFuzzer executables of fuzz/ link the same library objects. -ffp-contract=off: clang
# would otherwise fuse multiply-adds that GCC (ISO mode) does not, and the tests that compare a
# vectorised path with its scalar definition bit for bit must see the same arithmetic. Warnings
# are not errors here (clang-only warnings in code built with GCC and -Werror elsewhere).
ASAN_CONFIGURE_FLAGS = -G Ninja $(LAUNCHER_FLAGS) \
	-DCMAKE_CXX_COMPILER=clang++ \
	-DCMAKE_BUILD_TYPE=RelWithDebInfo \
	"-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
	-DCMAKE_CXX_FLAGS=-ffp-contract=off \
	-DROUGHSCOPE_BUILD_FUZZERS=ON \
	-DROUGHSCOPE_BUILD_TESTS=ON \
	-DROUGHSCOPE_BUILD_PYTHON=OFF \
	-DROUGHSCOPE_BUILD_BENCH=OFF \
	-DROUGHSCOPE_BUILD_CLI=ON \
	-DROUGHSCOPE_WERROR=OFF
FUZZ_CONFIGURE_FLAGS = $(ASAN_CONFIGURE_FLAGS)

# Any sanitizer report ends the process with exit code 86, which no roughscope command uses.
# For the CLI tests, ASan and LeakSanitizer reports also go to files, and tests/python/conftest.py
# fails the test during which one appeared, whatever exit code it expected (UBSan combined with
# ASan ignores log_path: its reports stay on stderr, with exit code 86).
SANITIZER_OPTIONS = halt_on_error=1:exitcode=86
SANITIZER_ENV = ASAN_OPTIONS=detect_leaks=1:$(SANITIZER_OPTIONS) \
	UBSAN_OPTIONS=print_stacktrace=1:$(SANITIZER_OPTIONS)
SANITIZER_LOG_DIR = $(CURDIR)/$(ASAN_BUILD)/sanitizer-reports
SANITIZER_CLI_ENV = \
	ASAN_OPTIONS=detect_leaks=1:$(SANITIZER_OPTIONS):log_path=$(SANITIZER_LOG_DIR)/report \
	UBSAN_OPTIONS=print_stacktrace=1:$(SANITIZER_OPTIONS):log_path=$(SANITIZER_LOG_DIR)/report \
	ROUGHSCOPE_SANITIZER_LOG_DIR=$(SANITIZER_LOG_DIR)

.PHONY: all deps configure build test demo sanitize fuzz bench lint format clean

all: build

deps:
	scripts/install-deps

configure: deps
	$(CMAKE) -S . -B $(BUILD) $(CONFIGURE_FLAGS)

build: configure
	$(CMAKE) --build $(BUILD) -j $(JOBS)

test: build
	$(CTEST) --test-dir $(BUILD) --output-on-failure -j $(JOBS) --no-tests=error

# The demo needs only the CLI and the Python module (not the tests, benchmarks or fuzz replays).
demo: configure
	$(CMAKE) --build $(BUILD) -j $(JOBS) --target roughscope_cli _core roughscope_python_package
	PYTHONPATH=$(BUILD)/python ROUGHSCOPE_CLI=$(BUILD)/bin/roughscope MPLBACKEND=Agg \
		$(PYTHON) -m roughscope.report --out $(REPORT_DIR)
	@echo "Report: $(REPORT_DIR)/index.html"

# Under AddressSanitizer + UBSan (the clang build $(ASAN_BUILD) above): the C++ tests (ctest
# labels "cpp" and "fuzz": the libFuzzer executables replay their corpus and regressions), then
# the CLI tests (pytest marker "cli", see DEVELOPERS.md) against the instrumented executable,
# with the Python module of the release build $(BUILD) (built here if missing) and
# ROUGHSCOPE_SANITIZED=1 (memory-measuring tests skip).
sanitize: configure
	$(CMAKE) --build $(BUILD) -j $(JOBS) --target _core roughscope_python_package
	$(CMAKE) -S . -B $(ASAN_BUILD) $(ASAN_CONFIGURE_FLAGS)
	$(CMAKE) --build $(ASAN_BUILD) -j $(JOBS)
	rm -rf $(SANITIZER_LOG_DIR) && mkdir -p $(SANITIZER_LOG_DIR)
	$(SANITIZER_ENV) \
		$(CTEST) --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS) -L '^(cpp|fuzz)$$' --no-tests=error
	$(SANITIZER_CLI_ENV) ROUGHSCOPE_SANITIZED=1 PYTHONPATH=$(CURDIR)/$(BUILD)/python \
		ROUGHSCOPE_CLI=$(CURDIR)/$(ASAN_BUILD)/bin/roughscope PYTHONDONTWRITEBYTECODE=1 MPLBACKEND=Agg \
		$(PYTHON) -m pytest -q -m cli -o cache_dir=$(CURDIR)/$(ASAN_BUILD)/.pytest_cache tests/python

# libFuzzer: builds $(FUZZ_BUILD) (the sanitizer build: nothing to compile after `make sanitize`)
# and runs every target of fuzz/ for FUZZ_SECONDS each (fuzz/run: fixed seed, a copy of the seed
# corpus, fails on any crash or report).
fuzz: deps
	$(CMAKE) -S . -B $(FUZZ_BUILD) $(FUZZ_CONFIGURE_FLAGS)
	$(CMAKE) --build $(FUZZ_BUILD) -j $(JOBS) --target roughscope_fuzzers
	FUZZ_SECONDS=$(FUZZ_SECONDS) fuzz/run $(FUZZ_BUILD)

# clang-format check + clang-tidy (.clang-format, .clang-tidy) on the project's sources.
lint: configure
	JOBS=$(JOBS) scripts/lint $(BUILD)

# Reformat every tracked C++ file in place.
format:
	git ls-files -- '*.cpp' '*.hpp' | xargs clang-format -i

bench: build
	$(BUILD)/bin/roughscope_bench
	@if [ -f bench/python_bench.py ]; then \
		echo "PYTHONPATH=$(BUILD)/python $(PYTHON) bench/python_bench.py"; \
		PYTHONPATH=$(BUILD)/python ROUGHSCOPE_CLI=$(BUILD)/bin/roughscope MPLBACKEND=Agg \
			$(PYTHON) bench/python_bench.py; \
	fi

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) build-fuzz out
