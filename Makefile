# The two commands: `make demo` and `make test`. Everything else is CMake.
BUILD ?= build
JOBS  ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
# Ninja when it is installed (scripts/install-deps.sh installs ninja-build): it keeps both cores
# busy through the whole build, where CMake's Makefiles left one idle about a tenth of the time
# (measured: docs/BENCHMARKS.md "Test suite and CI"). An existing build folder keeps the
# generator it was configured with.
GENERATOR ?= $(shell command -v ninja >/dev/null 2>&1 && echo Ninja)

.PHONY: all demo test test-slow deps configure build bench bench-quick clean python web

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) $(if $(GENERATOR),-G "$(GENERATOR)") -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

configure: deps $(BUILD)/CMakeCache.txt

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	./$(BUILD)/animkit demo -o out

# The fast suite (under a minute on 2 cores); `make test-slow` runs the cases marked slow
# (long end-to-end runs, tests/ak_test.h AK_RUN_SLOW), which .ci/run also runs.
test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -LE slow

test-slow: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -L slow

# The Python package in place: python/animkit/_core*.so beside the sources, so that
# PYTHONPATH=python finds `import animkit` (docs/python.md; pip install --no-build-isolation .
# installs it instead).
python: configure
	cmake --build $(BUILD) -j $(JOBS) --target animkit_python
	cp $(BUILD)/python/animkit/_core*.so python/animkit/

# Every benchmark (bench/bench_*, vs_rvo2 and bench_rigid_vs_bullet when built, the Python benches
# after `make python`) and every side-by-side harness of ../shared/peers (each skipped with a line
# when absent): full outputs and one SUMMARY.md under $(BUILD)/bench-results (scripts/bench.sh,
# docs/BENCHMARKS.md).
# `make bench-quick` runs the same pipeline at the smallest sizes (a check, not a measurement).
bench: build
	@bash scripts/bench.sh $(BUILD)

bench-quick: build
	@AK_BENCH_QUICK=1 bash scripts/bench.sh $(BUILD)

# animkit in a browser: the library compiled to WebAssembly (clang --target=wasm32-wasi, Debian's
# wasi-libc) and the page, into $(BUILD)/web (docs/web.md). Needs `scripts/install-deps.sh --web`;
# says what is missing otherwise. Serve it: python3 -m http.server -d $(BUILD)/web
web:
	@bash scripts/build-web.sh $(BUILD)/web

clean:
	rm -rf $(BUILD) build-asan build-scalar out
