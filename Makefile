# Entry points for a fresh Debian 12 machine. `make demo` installs what is missing, builds and runs the
# odometry on a simulated drive; `make test` does the same and runs every test but the long drives, which
# `make test-long` runs; `make bench` prints the speed figures; `make accuracy` the accuracy table on
# simulated sequences, `make accuracy-real` the one on the real KITTI-raw drives (docs/real_drives.md).
# `make test-sanitize` runs the suite under AddressSanitizer + UndefinedBehaviorSanitizer and the core's
# tests under ThreadSanitizer; `make fuzz` runs every libFuzzer target for FUZZ_SECONDS (needs clang, which it installs); `make rviz-screenshot` replays a simulated
# drive into rviz on a virtual screen and saves docs/rviz.png and docs/rviz_map.png; `make gpu-check` checks and measures the
# CUDA backend on a GPU machine.
SHELL := /bin/bash
# catkin's CMake needs Debian's python (with catkin_pkg) ahead of any other python3 on PATH.
export PATH := /usr/bin:$(PATH)

BUILD ?= build
JOBS ?= $(shell nproc)
SHARED_DATA ?= $(abspath ../shared/data)
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

DEB_PACKAGES := build-essential cmake catkin python3-catkin-pkg \
  libeigen3-dev libtbb-dev libyaml-cpp-dev libpcl-dev libgtest-dev gnuplot-nox \
  libroscpp-dev libnodelet-dev libnodeletlib-dev libnodeletlib-tools libtf2-ros-dev libtf2-eigen-dev \
  libpcl-ros-dev libpcl-conversions-dev librostest-dev python3-rostest libsensor-msgs-dev \
  libnav-msgs-dev librosbag-dev python3-rosbag rosout python3-roslaunch python3-rosmaster \
  libdiagnostic-updater-dev libstd-srvs-dev libgeometry-msgs-dev tf2-tools rviz libsqlite3-dev python3-numpy

.PHONY: deps build test test-long compat compat-poses test-sanitize test-asan test-tsan test-baseline test-aarch64 deps-aarch64 fuzz \
  bench demo accuracy accuracy-real soak rviz-screenshot gpu-check clean

# Installs only what is missing, so a second run needs no network.
deps:
	@missing=$$(for p in $(DEB_PACKAGES); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing:" $$missing; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get -o DPkg::Lock::Timeout=600 install -y -qq $$missing; \
	fi

# The CUDA backend is built when nvcc is found: on PATH, or where the CUDA toolkit installs it.
NVCC ?= $(shell command -v nvcc || ls /usr/local/cuda/bin/nvcc 2>/dev/null)

# CMAKE_ARGS: more options for the configure step (make compat builds with -DELO_NATIVE=OFF).
CMAKE_ARGS ?=
build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DELO_SHARED_DATA=$(SHARED_DATA) \
	  -DPython3_EXECUTABLE=/usr/bin/python3 -DPYTHON_EXECUTABLE=/usr/bin/python3 \
	  $(if $(NVCC),-DCMAKE_CUDA_COMPILER=$(NVCC)) $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS)

# Every test but the long simulated drives (labelled long, test/CMakeLists.txt), which test-long runs.
test: build
	cd $(BUILD) && ctest --output-on-failure -LE long -j$(JOBS)

test-long: build
	cd $(BUILD) && ctest --output-on-failure -L long -j$(JOBS)

# Sanitizer builds sit beside the normal one and are Release builds, like it (CMakeLists.txt,
# ELO_SANITIZE). A report fails the test that caused it; test/sanitizers/ holds the suppressions of what
# is not ours, each with its reason.
ASAN_BUILD ?= build-asan
TSAN_BUILD ?= build-tsan
SANITIZER_FILES := $(CURDIR)/test/sanitizers
SANITIZER_CMAKE := -DCMAKE_BUILD_TYPE=Release -DELO_SHARED_DATA=$(SHARED_DATA) \
  -DPython3_EXECUTABLE=/usr/bin/python3 -DPYTHON_EXECUTABLE=/usr/bin/python3
ASAN_ENV := ASAN_OPTIONS=detect_leaks=1:check_initialization_order=1 \
  LSAN_OPTIONS=suppressions=$(SANITIZER_FILES)/lsan.supp:print_suppressions=0 UBSAN_OPTIONS=print_stacktrace=1
TSAN_ENV := TSAN_OPTIONS=suppressions=$(SANITIZER_FILES)/tsan.supp:history_size=7

test-sanitize: test-asan test-tsan

# Every test, the ROS ones included, but the short demo, and what a sanitizer build does not build
# (test/CMakeLists.txt): the drives over simulated or real scans, 5 to 13 times their length under ASan,
# whose code runs under it in shorter tests, and the simulator's own tests, whose scenes take minutes
# under ASan (the simulator runs under it in the fixtures that make the rostests' bags). The normal
# build runs them all (make test).
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) $(SANITIZER_CMAKE) -DELO_SANITIZE=address,undefined
	cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && $(ASAN_ENV) ctest --output-on-failure -LE demo -j$(JOBS)

# The core library's tests: the threaded CPU kernels (TBB) and everything that calls them, the map's
# thread included; but its four simulated drives (BothModes/*, 40 s to 90 s each under TSan), whose
# kernels and threads the other tests run.
test-tsan: deps
	cmake -S . -B $(TSAN_BUILD) $(SANITIZER_CMAKE) -DELO_SANITIZE=thread
	cmake --build $(TSAN_BUILD) --target test_core -j$(JOBS)
	cd $(TSAN_BUILD) && $(TSAN_ENV) ctest --output-on-failure -L '^core$$' -E '^BothModes/' -j$(JOBS)

# The core's tests in a baseline x86-64 build (ELO_NATIVE=OFF: SSE2, so the scalar code instead of the
# AVX lanes, and no FMA), then its poses on the shared real scans against the -march=native build's
# (tools/poses_of.sh, tools/same_poses.sh). Only what those need is built. Without FMA, fusedMultiplyAdd()
# and Eigen round twice where the native build rounds once, so the poses differ in the last bits, which
# ICP carries to at most 0.9 mm over the 60 scans: the bound is about twice that (docs/platforms.md).
# CI builds the baseline on Debian 11 instead (make compat COMPAT_TARGETS=core, then compat-poses).
BASELINE_BUILD ?= build-baseline
BASELINE_POSE_BOUND ?= 0.002
REAL_SCANS := $(SHARED_DATA)/real/hdl64_drive_a
test-baseline: build
	cmake -S . -B $(BASELINE_BUILD) -DCMAKE_BUILD_TYPE=Release -DELO_NATIVE=OFF -DELO_CUDA=OFF \
	  -DELO_SHARED_DATA=$(SHARED_DATA) -DPython3_EXECUTABLE=/usr/bin/python3 -DPYTHON_EXECUTABLE=/usr/bin/python3
	cmake --build $(BASELINE_BUILD) --target test_core test_fault_cases test_backend_agreement elo_run -j$(JOBS)
	cd $(BASELINE_BUILD) && ctest --output-on-failure -L '^core$$' -j$(JOBS)
	tools/poses_of.sh $(BUILD) $(REAL_SCANS) $(BUILD)/poses
	tools/poses_of.sh $(BASELINE_BUILD) $(REAL_SCANS) $(BASELINE_BUILD)/poses
	tools/same_poses.sh $(BUILD)/poses $(BASELINE_BUILD)/poses $(BASELINE_POSE_BOUND)

# The ROS-free core and its tests cross-built for 64-bit ARM (cmake/aarch64-linux-gnu.cmake: Debian's
# cross compiler and arm64 multiarch packages, ELO_CORE_ONLY) and run under qemu-user. Emulated code runs
# many times slower, so the one test with a bound in seconds is left out (AARCH64_CTEST_EXCLUDE).
AARCH64_BUILD ?= build-aarch64
AARCH64_CTEST_EXCLUDE ?= ProcessedInBoundedTime
AARCH64_PACKAGES := cmake libeigen3-dev g++-aarch64-linux-gnu qemu-user libtbb-dev:arm64 libgtest-dev:arm64
deps-aarch64:
	@dpkg --print-foreign-architectures | grep -qx arm64 || $(SUDO) dpkg --add-architecture arm64
	@$(MAKE) --no-print-directory deps DEB_PACKAGES="$(AARCH64_PACKAGES)"

test-aarch64: deps-aarch64
	cmake -S . -B $(AARCH64_BUILD) -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake -DELO_CORE_ONLY=ON \
	  -DCMAKE_BUILD_TYPE=Release -DELO_CUDA=OFF -DELO_SHARED_DATA=$(SHARED_DATA)
	cmake --build $(AARCH64_BUILD) -j$(JOBS)
	cd $(AARCH64_BUILD) && ctest --output-on-failure -E '$(AARCH64_CTEST_EXCLUDE)' -j$(JOBS)

# libFuzzer over each reader of untrusted input (test/fuzz), FUZZ_SECONDS per target; tools/fuzz.sh
# says where the corpus grows and where a crasher lands.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_TARGETS := fuzz_cloud_conversion fuzz_cdr_point_cloud2 fuzz_cdr_imu fuzz_kitti_bin fuzz_pcd fuzz_kitti_text fuzz_config_yaml
fuzz: DEB_PACKAGES += clang libclang-rt-14-dev
fuzz: deps
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DELO_FUZZ=ON \
	  -DELO_SHARED_DATA=$(SHARED_DATA) -DPython3_EXECUTABLE=/usr/bin/python3 -DPYTHON_EXECUTABLE=/usr/bin/python3
	cmake --build $(FUZZ_BUILD) --target elo_fuzz_targets -j$(JOBS)
	$(ASAN_ENV) tools/fuzz.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

bench: build
	tools/bench.sh $(BUILD) $(SHARED_DATA)

# On a GPU machine: the agreement tests, compute-sanitizer and the CPU-against-GPU bench in one table
# (tools/gpu_check.sh; docs/cuda.md says how to run it from a build packed for a machine without ROS).
gpu-check: build
	tools/gpu_check.sh $(BUILD)/devel/lib/elo_odometry $(SHARED_DATA)/real/hdl64_drive_a

# The package built and tested on Debian 11 (bullseye, the nearest twin of Noetic's Ubuntu 20.04) in a
# debootstrap chroot cached in .compat/bullseye (tools/compat.sh; root or sudo). COMPAT_TARGETS=core, as CI
# runs it, builds everything as a baseline x86-64 build, runs the core tests only and writes the poses that
# compat-poses compares; COMPAT_TARGETS=deps only makes the chroot and installs its packages (CI does
# that first, in the background). COMPAT_RELEASE=trixie does the same on Debian 13 (GCC 14, CMake 3.31,
# PCL 1.15, roscpp 1.17), in .compat/trixie.
COMPAT_TARGETS ?= test
COMPAT_RELEASE ?= bullseye
compat:
	COMPAT_RELEASE=$(COMPAT_RELEASE) tools/compat.sh $(COMPAT_TARGETS)

# The poses that `make compat COMPAT_TARGETS=core` left in .compat/poses (Debian 11's baseline x86-64
# build: GCC 10, Eigen 3.3, no AVX, no FMA) against this machine's -march=native build's.
compat-poses: build
	tools/poses_of.sh $(BUILD) $(REAL_SCANS) $(BUILD)/poses
	tools/same_poses.sh $(BUILD)/poses $(or $(COMPAT_CACHE),.compat)/poses $(BASELINE_POSE_BOUND)

# The built-in default: a simulated 1 km urban HDL-64E drive, scored against its exact ground truth, then
# replayed from a bag through the ROS node. DEMO_FRAMES=60 makes it short; see tools/demo.sh.
demo: build
	tools/demo.sh $(BUILD) $(SHARED_DATA)

# The accuracy table over simulated worlds, sensors and modes.
accuracy: build
	tools/accuracy.sh $(BUILD) $(SHARED_DATA)

# The accuracy tables on the real KITTI-raw drives with ground truth under REAL_DRIVES (docs/real_drives.md):
# drift over 10-100 m segments with its breakdown, and starts in motion; KISS_RUN=path/to/kiss_run adds
# KISS-ICP's rows. Says where it looked and succeeds when there is no drive.
REAL_DRIVES ?= $(abspath ../real_drives)
accuracy-real: build
	tools/accuracy_real.sh $(BUILD) $(REAL_DRIVES)

# The soak test: SOAK_SCANS simulated HDL-64E scans (default 20000, 33 min at 10 Hz) through the nodelet at
# SOAK_RATE times the sensor's rate; fails when memory grows after warm-up or a scan goes unexplained.
SOAK_SCANS ?= 20000
SOAK_RATE ?= 1
soak: build
	tools/soak.sh $(BUILD) $(SOAK_SCANS) $(SOAK_RATE)

# docs/rviz.png and docs/rviz_map.png: a simulated drive replayed into rviz on a virtual screen (docs/rviz.md).
rviz-screenshot: DEB_PACKAGES += xvfb netpbm
rviz-screenshot: build
	tools/rviz_screenshot.sh $(BUILD) docs/rviz.png
	tools/rviz_screenshot.sh $(BUILD) docs/rviz_map.png "" rviz/elo_map.rviz

clean:
	rm -rf $(BUILD)
