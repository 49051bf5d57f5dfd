# Two commands: `make demo` and `make test`. Everything else is CMake (see CMakePresets.json).
PRESET ?= release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD_DIR := build/$(PRESET)

.PHONY: demo test deps configure build asan-test tsan-test fuzz format-check clean

deps:
	@bash cmake/install-deps.sh

# A build folder made by Unix Makefiles (before the presets named Ninja) is configured afresh.
configure: deps
	@fresh=; grep -qs '^CMAKE_GENERATOR:INTERNAL=Unix Makefiles$$' $(BUILD_DIR)/CMakeCache.txt && fresh=--fresh; \
	  cmake --preset $(PRESET) $$fresh >/dev/null

build: configure
	cmake --build --preset $(PRESET) -j $(JOBS)

# The demo needs its own CLI only (bvhlab-demo: the volumes demo.json uses): no tests, benchmarks or
# fuzzers, and 4 of the engine's 22 slots (12 of its 55 files), are built first.
demo: configure
	cmake --build --preset $(PRESET) -j $(JOBS) --target bvhlab_demo
	$(BUILD_DIR)/bench/bvhlab-demo demo --build-dir $(BUILD_DIR)

# What the tests run (target bvhlab_tests: all but the benchmark suites no test runs; `make build` adds them).
test: configure
	cmake --build --preset $(PRESET) -j $(JOBS) --target bvhlab_tests
	ctest --preset $(PRESET) -j $(JOBS)

# ASan + UBSan on the tests declared SANITIZED and the fuzz corpora: the build holds only what they need
# (tests/README.md, "Sanitizers and fuzzing"); every test runs in `make test`.
asan-test:
	$(MAKE) configure PRESET=asan
	cmake --build --preset asan --target bvhlab_sanitized_tests -j $(JOBS)
	ctest --preset asan -j $(JOBS)

# ThreadSanitizer on the multi-threaded query tests (ctest label `threads`), built alone.
tsan-test:
	$(MAKE) configure PRESET=tsan
	cmake --build --preset tsan --target test_robust_threads -j $(JOBS)
	ctest --preset tsan -j $(JOBS)

# libFuzzer targets: the asan build (clang, ASan + UBSan, fuzzer coverage) holds them, and `make asan-test`
# already replays their committed corpora (ctest label fuzz). This explores FUZZ_SECONDS per target
# (FUZZ_SEED fixes the exploration, as CI does; empty: a fresh seed each run).
FUZZ_SECONDS ?= 30
FUZZ_SEED ?=
fuzz:
	$(MAKE) configure PRESET=asan
	cmake --build --preset asan --target bvhlab_fuzzers -j $(JOBS)
	FUZZ_SEED=$(FUZZ_SEED) tests/fuzz/run_fuzzers.sh build/asan $(FUZZ_SECONDS)

# Every tracked C++ file must already be formatted as .clang-format says; lists the ones that are not.
format-check: deps
	git ls-files -z '*.cpp' '*.hpp' | xargs -0 clang-format --dry-run -Werror

clean:
	rm -rf build
