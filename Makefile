# mmm: the two commands of the README, and the helpers behind them.
#   make demo   install what is missing, build (Release), run the main job
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
  libsuitesparse-dev
# The browser test of the operator web UI (tests/web): headless Chromium and
# npm for playwright-core (nodejs itself may come from Debian or NodeSource).
WEB_TEST_PACKAGES := chromium
# Extra tools used by .ci/run (format and static analysis).
LINT_PACKAGES := clang-format clang-tidy


.PHONY: demo test build deps deps-lint configure bench format lint clean

# The most complete real job that exists today: the default atlas (built when
# missing or when its recipe changed), checked and pictured; a synthetic
# patient with its calibrated radiograph pair; a survey of every real surface;
# a study of the example workflow (created once; later runs reuse it).
demo: build $(ATLAS_DIR)/atlas.yaml
	@echo "== mmm demo: check of the default atlas ($(ATLAS_DIR)) =="
	$(BUILD_DIR)/bin/mmm atlas check $(ATLAS_DIR)
	@mkdir -p $(BUILD_DIR)/demo
	$(BUILD_DIR)/bin/mmm atlas show $(ATLAS_DIR) --png $(BUILD_DIR)/demo/atlas.png
	@echo "== mmm demo: synthetic patient 1 and its frontal/lateral radiographs =="
	@test -f $(BUILD_DIR)/demo/patient_1/ground_truth.json || \
	  $(BUILD_DIR)/bin/mmm patient synth --atlas $(ATLAS_DIR) --seed 1 -o $(BUILD_DIR)/demo/patient_1
	@echo "== mmm demo: survey of the Visible Human Female surfaces =="
	$(BUILD_DIR)/bin/mmm mesh survey $(DATA_DIR)/vhf --out $(BUILD_DIR)/demo/vhf --lod-faces 2000
	@echo "== mmm demo: survey of the OpenSim gait2392 bones (m -> mm) =="
	$(BUILD_DIR)/bin/mmm mesh survey $(DATA_DIR)/gait2392/Geometry --scale 1000 \
	  --out $(BUILD_DIR)/demo/gait2392
	@echo "== mmm demo: a study (schemas/examples/mesh_demo.yaml) on the VHF gluteus medius =="
	@test -d $(BUILD_DIR)/demo/study || $(BUILD_DIR)/bin/mmm study create $(BUILD_DIR)/demo/study \
	  --workflow schemas/examples/mesh_demo.yaml \
	  --input surface=$(DATA_DIR)/vhf/Right/VHF_Right_Muscle_GluteusMedius_smooth.stl
	$(BUILD_DIR)/bin/mmm run $(BUILD_DIR)/demo/study -j $(JOBS)
	$(BUILD_DIR)/bin/mmm status $(BUILD_DIR)/demo/study
	@echo "Atlas: $(ATLAS_DIR) (picture: $(BUILD_DIR)/demo/atlas.png); patient: $(BUILD_DIR)/demo/patient_1"
	@echo "  (radiographs/pair_preview.png, ground_truth.json); open $(BUILD_DIR)/demo/*/vtp/*.vtp"
	@echo "and $(BUILD_DIR)/demo/study/outputs/*.ply in ParaView; figures in $(BUILD_DIR)/demo/*/survey.csv"

# The default atlas: rebuilt when missing or when its recipe changes.
$(ATLAS_DIR)/atlas.yaml: $(RECIPE) | build
	@echo "== mmm demo: building the default atlas from $(RECIPE) =="
	$(BUILD_DIR)/bin/mmm atlas build $(RECIPE) -o $(ATLAS_DIR) --data $(DATA_DIR)

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

build: deps configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

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

bench: build
	./bench/run $(SUITE)

format: deps-lint
	git ls-files '*.h' '*.cpp' | xargs clang-format -i

lint: deps-lint configure
	./.ci/lint

clean:
	rm -rf $(BUILD_DIR)
