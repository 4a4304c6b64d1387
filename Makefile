# Rubble — top-level entry points. Each target installs missing Debian packages first (scripts/install-deps.sh).
#   make demo    install, build, run the demo (headless autopilot when there is no display)
#   make test    install, build, check formatting and layering, run all tests
#   make bench   install, build Release, run the benchmarks (CSV + PNG in bench/results/)
#   make build   install and build (RelWithDebInfo) into build/
#   make install     build Release (build-release/), then install headers, stripped libraries, CMake package,
#                    pkg-config files, the CLI and the Python module into PREFIX (default /usr/local)
#   make sanitize    clang ASan+UBSan build of the whole test suite (build-asan/) and TSan build of the runtime
#                    and Bullet tests (build-tsan/), both run by CTest (scripts/sanitize.sh)
#   make sanitize-ci what CI runs after make test: make sanitize, then every libFuzzer target for a fixed seed and
#                    input count (3-25 s each; scripts/fuzz.sh ci), so CI findings reproduce
#   make fuzz-smoke  every libFuzzer target for FUZZ_SECONDS (default 45) each with fresh seeds, in build-asan/
#   make stress      the chained-fracture stress test with STRESS_IMPACTS (default 10000) impacts
#   make soak        rubble-bench scene with continuous fire for SOAK_FRAMES (default 100000) frames
#   make blender-addon  build the Python module, install the Blender add-on integrations/blender/rubble_fracture
#                    into BLENDER_ADDONS (Blender 3.4's user add-on folder) pointing at it, and enable it

BUILD_DIR  ?= build
BUILD_TYPE ?= RelWithDebInfo
RELEASE_DIR ?= build-release
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=
PREFIX     ?= /usr/local
# The dependency installer runs again only when scripts/install-deps.sh changed since it last succeeded.
DEPS_STAMP  = .deps/core.stamp
DEPS_ALL_STAMP = .deps/all.stamp

BLENDER_ADDONS ?= $(HOME)/.config/blender/3.4/scripts/addons
FUZZ_SECONDS ?= 45
STRESS_IMPACTS ?= 10000
SOAK_FRAMES ?= 100000

.PHONY: all deps build release install test demo bench format format-check lint clean deps-clang sanitize sanitize-ci \
	fuzz-smoke stress soak blender-addon

all: build

deps: $(DEPS_STAMP)

$(DEPS_STAMP): scripts/install-deps.sh
	@bash scripts/install-deps.sh
	@mkdir -p $(@D) && touch $@

$(BUILD_DIR)/build.ninja: | $(DEPS_STAMP)
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_ARGS)

build: deps $(BUILD_DIR)/build.ninja
	cmake --build $(BUILD_DIR) -j $(JOBS)

install: release
	cmake --install $(RELEASE_DIR) --prefix $(PREFIX) --strip

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

deps-clang: $(DEPS_ALL_STAMP)

$(DEPS_ALL_STAMP): scripts/install-deps.sh
	@bash scripts/install-deps.sh all
	@mkdir -p $(@D) && touch $@

sanitize: deps-clang
	@bash scripts/sanitize.sh all

sanitize-ci: deps-clang
	@bash scripts/sanitize.sh ci

fuzz-smoke: deps-clang
	@bash scripts/fuzz.sh $(FUZZ_SECONDS)

stress: build
	RUBBLE_STRESS_IMPACTS=$(STRESS_IMPACTS) ctest --test-dir $(BUILD_DIR) --output-on-failure -L stress -V \
	    --timeout 7200

soak: release
	@bash scripts/soak.sh $(RELEASE_DIR) $(SOAK_FRAMES)

blender-addon: deps $(BUILD_DIR)/build.ninja
	cmake --build $(BUILD_DIR) -j $(JOBS) --target rubble_python
	rm -rf $(BLENDER_ADDONS)/rubble_fracture && mkdir -p $(BLENDER_ADDONS)
	cp -r integrations/blender/rubble_fracture $(BLENDER_ADDONS)/
	echo "$(abspath $(BUILD_DIR))/python" > $(BLENDER_ADDONS)/rubble_fracture/rubble_path.txt
	blender -b --python-exit-code 1 --python-expr "import addon_utils, bpy; \
	    addon_utils.enable('rubble_fracture', default_set=True, handle_error=None); bpy.ops.wm.save_userpref()"

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD_DIR) $(RELEASE_DIR)
