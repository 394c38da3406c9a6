# 64-bit ARM Linux boards (Raspberry Pi 4/5, Jetson, RK3588, i.MX8) with Debian's g++-aarch64-linux-gnu.
# Tests run under qemu-aarch64-static through ctest. Usage: cmake --preset aarch64, or
#   cmake -S . -B build/aarch64 -G Ninja --toolchain toolchain/aarch64-linux-gnu.cmake
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(DOCKCORE_CROSS_TRIPLE aarch64-linux-gnu)
set(DOCKCORE_CROSS_QEMU qemu-aarch64-static)
include(${CMAKE_CURRENT_LIST_DIR}/linux-cross-common.cmake)
