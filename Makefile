# roughscope — the two README commands (`make demo`, `make test`) and helpers.
# Every target that builds first installs the Debian dependencies
# (scripts/install-deps; a quick no-op once they are there).

BUILD      ?= build
ASAN_BUILD ?= build-asan
JOBS       ?= 2
PYTHON     ?= /usr/bin/python3
CMAKE      ?= cmake
CTEST      ?= ctest
REPORT_DIR ?= out/report
# Warnings as errors: ON in CI (.ci/run exports ROUGHSCOPE_WERROR=ON), OFF by default.
ROUGHSCOPE_WERROR ?= OFF

CONFIGURE_FLAGS = -G Ninja \
	-DCMAKE_BUILD_TYPE=Release \
	-DROUGHSCOPE_BUILD_TESTS=ON \
	-DROUGHSCOPE_BUILD_PYTHON=ON \
	-DROUGHSCOPE_BUILD_BENCH=ON \
	-DROUGHSCOPE_BUILD_CLI=ON \
	-DROUGHSCOPE_SANITIZE=OFF \
	-DROUGHSCOPE_WERROR=$(ROUGHSCOPE_WERROR) \
	-DPython3_EXECUTABLE=$(PYTHON)

ASAN_CONFIGURE_FLAGS = -G Ninja \
	-DCMAKE_BUILD_TYPE=RelWithDebInfo \
	-DROUGHSCOPE_BUILD_TESTS=ON \
	-DROUGHSCOPE_BUILD_PYTHON=OFF \
	-DROUGHSCOPE_BUILD_BENCH=OFF \
	-DROUGHSCOPE_SANITIZE=ON \
	-DROUGHSCOPE_WERROR=OFF

.PHONY: all deps configure build test demo sanitize bench lint format clean

all: build

deps:
	scripts/install-deps

configure: deps
	$(CMAKE) -S . -B $(BUILD) $(CONFIGURE_FLAGS)

build: configure
	$(CMAKE) --build $(BUILD) -j $(JOBS)

test: build
	$(CTEST) --test-dir $(BUILD) --output-on-failure -j $(JOBS) --no-tests=error

demo: build
	PYTHONPATH=$(BUILD)/python ROUGHSCOPE_CLI=$(BUILD)/bin/roughscope MPLBACKEND=Agg \
		$(PYTHON) -m roughscope.report --out $(REPORT_DIR)
	@echo "Report: $(REPORT_DIR)/index.html"

# C++ tests only (ctest label "cpp"), under AddressSanitizer + UBSan. Warnings are not errors
# here: GCC's flow warnings give false positives under -fsanitize (the Release build has -Werror).
sanitize: deps
	$(CMAKE) -S . -B $(ASAN_BUILD) $(ASAN_CONFIGURE_FLAGS)
	$(CMAKE) --build $(ASAN_BUILD) -j $(JOBS)
	ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
		$(CTEST) --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS) -L '^cpp$$' --no-tests=error

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
	rm -rf $(BUILD) $(ASAN_BUILD) out
