# 32-bit ARM Linux boards with a hard-float ABI (Raspberry Pi 2/3 32-bit OS, BeagleBone, i.MX6, STM32MP1) with
# Debian's g++-arm-linux-gnueabihf (ARMv7-A, VFPv3-D16, Thumb-2). Tests run under qemu-arm-static through ctest.
set(CMAKE_SYSTEM_PROCESSOR arm)
set(DOCKCORE_CROSS_TRIPLE arm-linux-gnueabihf)
set(DOCKCORE_CROSS_QEMU qemu-arm-static)
include(${CMAKE_CURRENT_LIST_DIR}/linux-cross-common.cmake)
# GCC notes on every std::vector<Eigen...> that the 32-bit ARM ABI for such arguments changed in GCC 7.1: noise for a
# tree built by one compiler.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")
