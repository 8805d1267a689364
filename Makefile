# Thin wrapper over CMake. `make demo` and `make test` do all set-up on a fresh Debian 12.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: all deps configure build build-binary test tsan demo bench format clean

all: build

deps:
	scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD) -j$(JOBS)

# The `arucoslam` binary alone (no tests or benchmarks): what the demo runs.
build-binary: configure
	cmake --build $(BUILD) -j$(JOBS) --target arucoslam

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)
	$(MAKE) tsan

# ThreadSanitizer build (build-tsan/) of the threaded tests; `make test` runs it last.
tsan: deps
	scripts/tsan-tests.sh build-tsan

demo: build-binary
	$(BUILD)/bin/arucoslam demo --out out/demo

bench: build
	@for b in $(BUILD)/bench/*_bench; do echo "== $$b"; $$b; done

format:
	find src bench -name '*.h' -o -name '*.cc' | xargs clang-format -i

clean:
	rm -rf $(BUILD)
