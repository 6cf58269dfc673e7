# Debian packages (`cpack -G DEB` in the build folder): patrolmap, the two programs with the shipped vocabulary and
# configuration, its dependencies found by dpkg-shlibdeps; and libpatrolmap-dev, the stage libraries, headers and
# the CMake package (find_package(patrolmap)), depending on the -dev packages those need.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME patrolmap)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "patrolmap developers <patrolmap@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Topological appearance maps and change detection for repeated patrol flights")
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime development)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME patrolmap)
if(CMAKE_CROSSCOMPILING)
  # dpkg-shlibdeps reads the dpkg database of the machine it runs on, which holds no arm64 libraries:
  # scripts/cross_arm64.sh names the packages of the libraries the programs need, from its sysroot.
  set(PATROLMAP_DEB_RUNTIME_DEPENDS "" CACHE STRING "Depends of the runtime package when cross-building")
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "${PATROLMAP_DEB_RUNTIME_DEPENDS}")
else()
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
endif()
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_NAME libpatrolmap-dev)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_DEPENDS
    "libopencv-dev (>= 4.5), libeigen3-dev, libyaml-cpp-dev, libspdlog-dev, libcli11-dev, libboost-dev, \
nlohmann-json3-dev, libceres-dev, libnanoflann-dev, libsqlite3-dev")
include(CPack)
