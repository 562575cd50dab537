# mmm: the two commands of the README, and the helpers behind them.
#   make demo   install what is missing, build mmm (Release), run the default study end to end
#   make test   install what is missing, build (Release), run the whole test suite
# Other targets: build, deps, bench [SUITE=mesh], format, lint, clean.

BUILD_DIR  ?= build
BUILD_TYPE ?= Release
DATA_DIR   ?= $(abspath ../shared/data)
JOBS       ?= $(shell nproc)
SUITE      ?= mesh
ATLAS_DIR  ?= $(BUILD_DIR)/atlas/vhf_right_leg
RECIPE     ?= schemas/recipes/vhf_right_leg.yaml

# Debian 12 packages needed to build, test and benchmark mmm.
APT_PACKAGES := build-essential cmake ninja-build pkg-config python3 \
  libeigen3-dev libopenmesh-dev libceres-dev libyaml-cpp-dev libspdlog-dev libfmt-dev \
  libtinyxml2-dev nlohmann-json3-dev libcli11-dev libsqlite3-dev zlib1g-dev \
  libgtest-dev libgmock-dev googletest libbenchmark-dev libcpp-httplib-dev \
  libsuitesparse-dev libssl-dev libspng-dev libgdcm-dev python3-pydicom python3-numpy python3-pil slurm-wlm munge ccache
# The browser test of the operator web UI (tests/web): headless Chromium and
# npm for playwright-core (nodejs itself may come from Debian or NodeSource).
WEB_TEST_PACKAGES := chromium
# Extra tools used by .ci/run (format and static analysis; clang and its
# sanitizer runtimes compile the sanitizer builds).
LINT_PACKAGES := clang-format clang-tidy
SANITIZER_PACKAGES := clang libclang-rt-14-dev


.PHONY: demo test build build-mmm deps deps-lint deps-sanitize configure bench fuzz format lint clean

# The default study end to end (cmake/demo.sh): the default atlas (built when
# missing or when its recipe changed), synthetic patient 1 with its calibrated
# radiograph pair, a study of workflows/default.yaml run to the landmark
# station, a clearly labelled scripted operator placing the landmarks (noisy
# clicks from the patient's ground truth), then scaling, motion, wrapping and
# fibres. MANUAL=1 leaves the landmark task open for a person instead.
# DICOM=1 gives the study the patient's radiographs as DICOM files (with an
# invented identity, removed when the study is created) instead of PNGs.
# Interrupt it at any point and run it again: it goes on where it stopped.
MANUAL ?= 0
DICOM ?= 0
demo: build-mmm $(ATLAS_DIR)/atlas.yaml
	DICOM=$(DICOM) ./cmake/demo.sh $(BUILD_DIR)/bin/mmm $(ATLAS_DIR) $(DATA_DIR) $(BUILD_DIR)/demo $(JOBS) $(MANUAL)

# The default atlas: rebuilt when missing or when its recipe changes.
$(ATLAS_DIR)/atlas.yaml: $(RECIPE) | build-mmm
	@echo "== mmm demo: building the default atlas from $(RECIPE) =="
	$(BUILD_DIR)/bin/mmm atlas build $(RECIPE) -o $(ATLAS_DIR) --data $(DATA_DIR)

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

build: deps configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

# Only the mmm command (no tests, no benchmarks): what make demo needs.
build-mmm: deps configure
	cmake --build $(BUILD_DIR) -j $(JOBS) --target mmm

configure:
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DMMM_DATA_DIR=$(DATA_DIR)

# Installs only the packages that are missing, so it is quiet and fast when
# everything is there (idempotent).
deps:
	@./cmake/install_apt_packages.sh $(APT_PACKAGES) $(WEB_TEST_PACKAGES)
	@command -v npm >/dev/null || ./cmake/install_apt_packages.sh nodejs npm
	@test tests/web/node_modules/.package-lock.json -nt tests/web/package-lock.json || \
	  (cd tests/web && npm ci --no-audit --no-fund)

deps-lint:
	@./cmake/install_apt_packages.sh $(LINT_PACKAGES)

deps-sanitize:
	@./cmake/install_apt_packages.sh $(SANITIZER_PACKAGES)

# The fuzz targets (fuzz/): a clang build with AddressSanitizer and
# UndefinedBehaviorSanitizer in build-fuzz/, every regression input, then
# FUZZ_SECONDS of fuzzing per target (FUZZ_TARGETS: a subset).
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?=
fuzz: deps deps-sanitize
	cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DMMM_SANITIZE=address,undefined -DMMM_FUZZ=ON \
	  -DMMM_BUILD_TESTS=OFF -DMMM_BUILD_BENCH=OFF -DMMM_DATA_DIR=$(DATA_DIR)
	cmake --build build-fuzz -j $(JOBS)
	./fuzz/run build-fuzz $(FUZZ_SECONDS) $(FUZZ_TARGETS)

bench: build
	./bench/run $(SUITE)

format: deps-lint
	git ls-files '*.h' '*.cpp' | xargs clang-format -i

lint: deps-lint
	./.ci/lint

clean:
	rm -rf $(BUILD_DIR)
