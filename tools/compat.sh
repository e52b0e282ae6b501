#!/usr/bin/env bash
# Builds and tests the package on an older or newer Debian than the machine's, in a chroot made with
# debootstrap, from a clean copy of this tree (what git tracks or would track: no build directories), with
# the `make deps` and `make` targets a user runs. The release is COMPAT_RELEASE: bullseye by default
# (Debian 11: GCC 10, CMake 3.18, TBB 2020, PCL 1.11, roscpp 1.15 as on Noetic; what CI runs), or trixie
# (Debian 13: GCC 14, CMake 3.31, PCL 1.15, Boost 1.83, roscpp 1.17), or any release Debian's mirror and
# this machine's debootstrap know. Root only (it mounts; sudo is used when not root). Usage:
#   [COMPAT_RELEASE=trixie] tools/compat.sh [MAKE_TARGET... | core]
# MAKE_TARGET defaults to `test`. `core` is CI's share of the run: everything built as a baseline x86-64
# build (-DELO_NATIVE=OFF: no AVX, no FMA), the core tests (ctest -L core), and elo_run's poses on the
# shared real scans written to COMPAT_CACHE/poses (tools/poses_of.sh), which `make compat-poses` compares
# with this machine's -march=native build's. Environment: COMPAT_RELEASE (default bullseye), COMPAT_CACHE
# (default .compat/ in the tree, ignored by git: one chroot per release, COMPAT_CACHE/<release>, kept
# between runs so that a second run needs no download), COMPAT_MIRROR (default Debian's, deb.debian.org),
# JOBS (default nproc). The shared data (../shared/data) is mounted read-only when present.
set -euo pipefail
tree="$(cd "$(dirname "$0")/.." && pwd)"
cache=${COMPAT_CACHE:-$tree/.compat}
mirror=${COMPAT_MIRROR:-http://deb.debian.org/debian}
jobs=${JOBS:-$(nproc)}
release=${COMPAT_RELEASE:-bullseye}
chroot_dir="$cache/$release"
src="/src/elo_odometry"  # the tree's copy, inside the chroot; ../shared/data beside it as in a checkout
shared="$tree/../shared/data"
targets=("${@:-test}")
sudo=""
[ "$(id -u)" = 0 ] || sudo=sudo

step() {
  echo "=== compat: $* (at ${SECONDS} s)"
}

# The base system, once: debootstrap into a temporary directory and rename it when complete, so that an
# interrupted run leaves no half-made chroot behind to be taken for a cached one.
if [ ! -x "$chroot_dir/usr/bin/apt-get" ]; then
  command -v debootstrap >/dev/null || $sudo apt-get -o DPkg::Lock::Timeout=900 install -y -qq debootstrap
  step "debootstrap $release from $mirror into $chroot_dir"
  $sudo rm -rf "$chroot_dir.partial"
  mkdir -p "$cache"
  $sudo debootstrap --variant=minbase --include=make "$release" "$chroot_dir.partial" "$mirror"
  # A throwaway system: no fsync per file, no manuals or recommended extras (make deps names every
  # package the build and the tests need): apt takes less time in it.
  echo force-unsafe-io | $sudo tee "$chroot_dir.partial/etc/dpkg/dpkg.cfg.d/90elo-unsafe-io" >/dev/null
  printf 'path-exclude=/usr/share/%s/*\n' doc man info locale | $sudo tee "$chroot_dir.partial/etc/dpkg/dpkg.cfg.d/90elo-no-docs" >/dev/null
  echo 'APT::Install-Recommends "false";' | $sudo tee "$chroot_dir.partial/etc/apt/apt.conf.d/90elo-no-recommends" >/dev/null
  $sudo mv "$chroot_dir.partial" "$chroot_dir"
fi

# The chroot holds its release's ROS packages: catkin and rospack, which crawl the source tree (and a
# workspace's src/), must not take them for packages of the workspace.
touch "$cache/CATKIN_IGNORE" "$cache/rospack_nosubdirs"

# Mounts for the run, undone on any exit, in reverse order; the shared data read-only, so that nothing in
# the chroot can change it.
mounted=()
cleanup() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    $sudo umount "${mounted[i]}" || $sudo umount -l "${mounted[i]}" || true
  done
}
trap cleanup EXIT
mount_into() {  # mount_into TARGET_IN_CHROOT MOUNT_ARGS...
  local target="$chroot_dir$1"
  shift
  $sudo mkdir -p "$target"
  $sudo mount "$@" "$target"
  mounted+=("$target")
}
mount_into /proc -t proc proc
mount_into /sys -t sysfs sysfs
mount_into /dev --bind /dev
mount_into /dev/pts --bind /dev/pts
$sudo cp /etc/resolv.conf "$chroot_dir/etc/resolv.conf"
# debootstrap writes no /etc/hosts, and roslaunch must resolve localhost. The machine's own name too (the
# chroot shares the hostname), which roslaunch looks up: without it the lookup goes to DNS, and issue 40's
# trixie run had rostests that could not reach their own master (in the network namespace the lookup fails
# at once, and they passed without it). Checked on every run: a cached chroot may outlive the hostname.
grep -qs localhost "$chroot_dir/etc/hosts" || printf '127.0.0.1 localhost\n::1 localhost\n' | $sudo tee -a "$chroot_dir/etc/hosts" >/dev/null
host_name=$(uname -n)
grep -qsw -- "$host_name" "$chroot_dir/etc/hosts" || printf '127.0.1.1 %s\n' "$host_name" | $sudo tee -a "$chroot_dir/etc/hosts" >/dev/null
if [ -d "$shared" ]; then
  mount_into /src/shared/data --bind "$shared"
  $sudo mount -o remount,ro,bind "$chroot_dir/src/shared/data"
fi

step "copy the tree to $src"
$sudo rm -rf "$chroot_dir$src"
$sudo mkdir -p "$chroot_dir$src"
# Tracked and untracked-but-not-ignored files as they are now; a tracked file deleted here is left out.
(cd "$tree" && git ls-files -z --cached --others --exclude-standard |
  xargs -0 -I{} sh -c 'test -e "$1" && printf "%s\0" "$1"' _ {} |
  tar --null -T - -cf -) | $sudo tar -xf - -C "$chroot_dir$src"

# COMMAND in the tree's copy, in a clean environment. With --isolated, in a network namespace of its own
# with only loopback, where the kernel allows one, so that the tests' ROS masters meet no other on this
# machine (ROS_HOSTNAME=localhost: the one name there is). ccache is used where the chroot has it
# (installed by hand for quick local re-runs; CI's chroot has none).
in_chroot() {  # in_chroot [--isolated] COMMAND
  local isolate=()
  if [ "$1" = --isolated ]; then
    shift
    if command -v ip >/dev/null && $sudo unshare --net true 2>/dev/null; then
      isolate=(unshare --net sh -c 'ip link set lo up && exec "$@"' _)
    fi
  fi
  local launcher=""
  [ -x "$chroot_dir/usr/bin/ccache" ] && launcher=ccache
  $sudo "${isolate[@]}" chroot "$chroot_dir" env -i HOME=/root LANG=C.UTF-8 TERM=dumb ROS_HOSTNAME=localhost \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin ${launcher:+CMAKE_CXX_COMPILER_LAUNCHER=$launcher} \
    bash -c "cd $src && $1"
}

step "make deps (installs what $release lacks; nothing on a cached chroot)"
in_chroot "apt-get update -qq && make deps"

if [ "${targets[*]}" = core ]; then
  step "make build CMAKE_ARGS=-DELO_NATIVE=OFF, ctest -L core, the poses on the real scans"
  in_chroot --isolated "make build JOBS=$jobs CMAKE_ARGS=-DELO_NATIVE=OFF && (cd build && ctest --output-on-failure -L core -j$jobs) && tools/poses_of.sh build ../shared/data/real/hdl64_drive_a build/poses"
  rm -rf "$cache/poses"
  cp -r "$chroot_dir$src/build/poses" "$cache/poses"
else
  step "make ${targets[*]}"
  in_chroot --isolated "make ${targets[*]} JOBS=$jobs"
fi
step "done: Debian $(cat "$chroot_dir/etc/debian_version") ($release) passed"
