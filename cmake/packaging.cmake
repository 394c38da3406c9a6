# Debian packages: `cpack -G DEB` in a build tree gives dockcore_<version>_<arch>.deb with dockd, dockctl,
# dock-decode, the systemd unit and the example config (their install() rules live beside the targets; dock-decode's
# is here because tools/ has no other installable program). Architecture follows the compiler: amd64 from the
# default preset, arm64 from the aarch64 preset, armhf from armhf.
include(GNUInstallDirs)
if(TARGET dock-decode)
  install(TARGETS dock-decode RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(_deb_arch arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^arm")
  set(_deb_arch armhf)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64)$")
  set(_deb_arch amd64)
else()
  set(_deb_arch ${CMAKE_SYSTEM_PROCESSOR})
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME dockcore)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "dockcore")
set(CPACK_PACKAGE_CONTACT "dockcore maintainers <dockcore@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Autonomous docking for mobile robots: dockd daemon, dockctl, dock-decode")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # dockcore_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${_deb_arch})
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
# Written by hand rather than dpkg-shlibdeps, which cannot resolve a cross build's libraries on the build host.
set(_deb_depends "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, libtomlplusplus3 (>= 3.3)")
if(TARGET dockd)
  get_target_property(_dockd_libs dockd LINK_LIBRARIES)
  if(_dockd_libs MATCHES "LIBSYSTEMD")
    string(APPEND _deb_depends ", libsystemd0")
  endif()
  # dockd's own camera detector (docs/camera.md) links libapriltag.
  if(_dockd_libs MATCHES "dockcore_vision")
    string(APPEND _deb_depends ", libapriltag3 (>= 3.3)")
  endif()
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${_deb_depends}")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "can-utils")
include(CPack)

# Build the package, unpack it into a scratch root with dpkg-deb -x and run `dockd --help` from there: the package
# holds a dockd that starts, the unit and the example config. Native builds only (the packaged dockd must run here).
if(DOCKCORE_BUILD_TESTS AND NOT CMAKE_CROSSCOMPILING AND TARGET dockd)
  add_test(NAME package_deb_install
    COMMAND ${CMAKE_COMMAND} -DBUILD=${CMAKE_BINARY_DIR} -DWORK=${CMAKE_BINARY_DIR}/package_deb_install
      -DARCH=${_deb_arch} -P ${CMAKE_CURRENT_LIST_DIR}/package_smoke.cmake)
  set_tests_properties(package_deb_install PROPERTIES TIMEOUT 300)
endif()
