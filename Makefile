# mmm: the two commands of the README, and the helpers behind them.
#   make demo   install what is missing, build (Release), run the main job
#   make test   install what is missing, build (Release), run the whole test suite
# Other targets: build, deps, bench [SUITE=mesh], format, lint, clean.

BUILD_DIR  ?= build
BUILD_TYPE ?= Release
DATA_DIR   ?= $(abspath ../shared/data)
JOBS       ?= $(shell nproc)
SUITE      ?= mesh

# Debian 12 packages needed to build, test and benchmark mmm.
APT_PACKAGES := build-essential cmake ninja-build pkg-config python3 \
  libeigen3-dev libopenmesh-dev libceres-dev libyaml-cpp-dev libspdlog-dev libfmt-dev \
  libtinyxml2-dev nlohmann-json3-dev libcli11-dev libsqlite3-dev zlib1g-dev \
  libgtest-dev libgmock-dev googletest libbenchmark-dev
# Extra tools used by .ci/run (format and static analysis).
LINT_PACKAGES := clang-format clang-tidy


.PHONY: demo test build deps deps-lint configure bench format lint clean

# The most complete real job that exists today: check, measure and convert
# every surface of the atlas data (VHF in mm; OpenSim geometry in m, scaled),
# then a study of the example workflow (created once; later runs reuse it).
demo: build
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
	@echo "Open $(BUILD_DIR)/demo/*/vtp/*.vtp and $(BUILD_DIR)/demo/study/outputs/*.ply in ParaView;"
	@echo "figures in $(BUILD_DIR)/demo/*/survey.csv and $(BUILD_DIR)/demo/study/outputs/report.json"

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

build: deps configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

configure:
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DMMM_DATA_DIR=$(DATA_DIR)

# Installs only the packages that are missing, so it is quiet and fast when
# everything is there (idempotent).
deps:
	@./cmake/install_apt_packages.sh $(APT_PACKAGES)

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
