# Rubble — top-level entry points. Each target installs missing Debian packages first (scripts/install-deps.sh).
#   make demo    install, build, run the demo (headless autopilot when there is no display)
#   make test    install, build, check formatting and layering, run all tests
#   make bench   install, build Release, run the benchmarks (CSV + PNG in bench/results/)
#   make build   install and build (RelWithDebInfo) into build/

BUILD_DIR  ?= build
BUILD_TYPE ?= RelWithDebInfo
RELEASE_DIR ?= build-release
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=

.PHONY: all deps build release test demo bench format format-check lint clean

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD_DIR)/build.ninja: | deps
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_ARGS)

build: deps $(BUILD_DIR)/build.ninja
	cmake --build $(BUILD_DIR) -j $(JOBS)

release: deps
	@[ -f $(RELEASE_DIR)/build.ninja ] || cmake -S . -B $(RELEASE_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	    -DRUBBLE_BUILD_TESTS=OFF $(CMAKE_ARGS)
	cmake --build $(RELEASE_DIR) -j $(JOBS)

lint: deps
	@bash scripts/check-format.sh
	@bash scripts/check-layering.sh

test: lint build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) --timeout 600

demo: build
	@bash scripts/run-demo.sh $(BUILD_DIR)

bench: release
	@bash scripts/run-bench.sh $(RELEASE_DIR)

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD_DIR) $(RELEASE_DIR)
