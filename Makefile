# Two commands: `make demo` and `make test`. Everything else is CMake (see CMakePresets.json).
PRESET ?= release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD_DIR := build/$(PRESET)

.PHONY: demo test deps configure build asan-test clean

deps:
	@bash cmake/install-deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	cmake --build --preset $(PRESET) -j $(JOBS)

demo: build
	$(BUILD_DIR)/bench/bvhlab demo --build-dir $(BUILD_DIR)

test: build
	ctest --preset $(PRESET) -j $(JOBS)

asan-test:
	$(MAKE) test PRESET=asan

clean:
	rm -rf build
