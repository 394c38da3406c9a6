# Shared part of the Debian multiarch cross toolchains (aarch64-linux-gnu.cmake, arm-linux-gnueabihf.cmake).
# The including file sets DOCKCORE_CROSS_TRIPLE (GNU triple = Debian multiarch tuple) and DOCKCORE_CROSS_QEMU.
#
# Where target things live on Debian: the cross compiler's own libc/libstdc++ in /usr/<triple>
# (libc6-dev-<arch>-cross), and multiarch -dev packages (libcpputest-dev:arm64, libtomlplusplus-dev:arm64) in
# /usr/lib/<triple> with their headers in /usr/include. So the find roots are /usr/<triple> and /, and every find_*
# is restricted to them (ONLY) while CMAKE_LIBRARY_ARCHITECTURE makes find_library/find_package look in
# lib/<triple> and never in the host's lib/x86_64-linux-gnu. Header-only, arch-independent packages (Eigen,
# nlohmann-json, CLI11: /usr/share, /usr/include) are found from the host through the "/" root.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_C_COMPILER ${DOCKCORE_CROSS_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${DOCKCORE_CROSS_TRIPLE}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${DOCKCORE_CROSS_TRIPLE})
set(CMAKE_FIND_ROOT_PATH /usr/${DOCKCORE_CROSS_TRIPLE} /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)   # build tools (nm, pkg-config, python) are the host's
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config must see only the target's .pc files (cpputest), never the host's /usr/lib/x86_64-linux-gnu/pkgconfig.
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/${DOCKCORE_CROSS_TRIPLE}/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_PATH} "")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "")

# binfmt_misc is not registered on the build machines, so ctest runs each target binary through qemu-user.
# -L: the cross libc's dynamic loader; libraries it does not have there (multiarch libtomlplusplus.so,
# libstdc++ of the multiarch package) qemu falls back to the host path /usr/lib/<triple>.
set(CMAKE_CROSSCOMPILING_EMULATOR ${DOCKCORE_CROSS_QEMU};-L;/usr/${DOCKCORE_CROSS_TRIPLE})
