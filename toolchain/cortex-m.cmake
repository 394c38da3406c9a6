# Bare-metal Arm Cortex-M (no OS) with Debian's gcc-arm-none-eabi + newlib (libnewlib-arm-none-eabi,
# libstdc++-arm-none-eabi-newlib). Default CPU: Cortex-M7 with the double-precision FPU (fpv5-d16, e.g.
# STM32F76x/H7, i.MX RT10xx); for a single-precision FPU (Cortex-M4F, M7 with fpv5-sp-d16) pass
# -DDOCKCORE_CORTEX_M_FLAGS="-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard" and build with
# DOCKCORE_REAL_FLOAT=ON (the cortex-m-float preset does the latter).
# Only core (and the example firmware) builds for it: see DOCKCORE_CORE_ONLY in the top-level CMakeLists.txt.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)

# No OS to run executables in try_compile: test the compiler by building a static library.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(DOCKCORE_CORTEX_M_FLAGS "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb"
    CACHE STRING "CPU/FPU/ABI flags for the Cortex-M target")
# Each function/object in its own section so the firmware link (--gc-sections) keeps only what is reachable.
# -Wno-psabi: GCC notes that Eigen's by-value parameters changed ABI in GCC 7.1; everything here is built by one compiler.
set(CMAKE_C_FLAGS_INIT "${DOCKCORE_CORTEX_M_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${DOCKCORE_CORTEX_M_FLAGS} -ffunction-sections -fdata-sections -fno-exceptions -fno-rtti -fno-threadsafe-statics -Wno-psabi")
set(CMAKE_ASM_FLAGS_INIT "${DOCKCORE_CORTEX_M_FLAGS}")
# newlib-nano: the small printf/malloc variants (the firmware uses neither, but the C runtime start-up links).
set(CMAKE_EXE_LINKER_FLAGS_INIT "${DOCKCORE_CORTEX_M_FLAGS} --specs=nano.specs -Wl,--gc-sections")

# Eigen is header-only: take it from the host. Nothing else is searched for.
set(CMAKE_FIND_ROOT_PATH /usr/lib/arm-none-eabi /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
