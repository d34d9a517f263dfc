# Thin wrapper: dependencies, build, tests, demo. The build itself is CMake (see CMakePresets.json).
SHELL := /bin/bash
BUILD_DIR ?= build/dev
JOBS ?= $(shell nproc)
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# Debian bookworm packages, nothing else (no downloads at build time).
DEB_PACKAGES := build-essential cmake ninja-build pkg-config \
  libopencv-dev libeigen3-dev libceres-dev libgoogle-glog-dev libgflags-dev libyaml-cpp-dev \
  libcli11-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev \
  zlib1g-dev opencv-doc python3 python3-numpy chromium curl

# BUILD_DIR is configured with the preset of CMakePresets.json whose binaryDir it is (build/dev:
# dev, build/release: release, ...); any other folder directly, with dev's build type.
PRESET := $(shell awk -v d='"$${sourceDir}/$(BUILD_DIR)"' \
  '/"name":/ {n = $$0; sub(/.*"name": *"/, "", n); sub(/".*/, "", n)} \
   /"binaryDir":/ && index($$0, d) {print n; exit}' CMakePresets.json 2>/dev/null)
ifneq ($(PRESET),)
CONFIGURE := cmake --preset $(PRESET)
else
CONFIGURE := cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
endif

.PHONY: deps configure build test demo bench clean

deps:
	@missing=$$(for p in $(DEB_PACKAGES); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages: $$missing"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	else echo "All Debian packages present."; fi

configure: deps
	@if [ ! -f $(BUILD_DIR)/build.ninja ]; then $(CONFIGURE); fi

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

demo: build
	./scripts/demo.sh $(BUILD_DIR)/bin/dynorb

bench: build
	$(BUILD_DIR)/bench/dynorb_microbench

clean:
	rm -rf build
