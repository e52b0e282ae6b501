# Cross build for 64-bit ARM Linux (Jetson, Graviton, Raspberry Pi 4/5) with Debian's
# g++-aarch64-linux-gnu, against the arm64 packages of Debian's multiarch (`dpkg --add-architecture
# arm64`), which install into /usr/lib/aarch64-linux-gnu; the tests run under qemu-user. With
# -DELO_CORE_ONLY=ON it needs only Eigen, TBB and GoogleTest: `make test-aarch64` (docs/platforms.md).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# find_package() and find_library() then search the arm64 directories (lib/aarch64-linux-gnu), never
# the build machine's lib/x86_64-linux-gnu.
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
# ctest and gtest_discover_tests() run the test programs through it.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64)
