# Cross-building for arm64 (the computers UAVs carry) with Debian's aarch64-linux-gnu compiler against a sysroot
# of Debian's arm64 packages, as scripts/cross_arm64.sh sets it up:
#   cmake -S . -B build-arm64/build -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
#     -DPATROLMAP_ARM64_SYSROOT=$PWD/build-arm64/sysroot
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

if(NOT PATROLMAP_ARM64_SYSROOT)
  set(PATROLMAP_ARM64_SYSROOT "$ENV{PATROLMAP_ARM64_SYSROOT}")
endif()
if(NOT IS_DIRECTORY "${PATROLMAP_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu")
  message(FATAL_ERROR "PATROLMAP_ARM64_SYSROOT (${PATROLMAP_ARM64_SYSROOT}) is not an arm64 sysroot: "
                      "scripts/cross_arm64.sh sets one up")
endif()
# Try-compiles run in other folders: hand them the sysroot too.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES PATROLMAP_ARM64_SYSROOT)
set(CMAKE_SYSROOT "${PATROLMAP_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH "${PATROLMAP_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_LIBDIR}
    "${PATROLMAP_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${PATROLMAP_ARM64_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${PATROLMAP_ARM64_SYSROOT}")
# GCC notes on every std::pair<double, double> passed by value that its arm64 ABI changed in GCC 10.1; everything
# here is built by one compiler.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")
# The libraries' own dependencies (e.g. OpenCV's GDAL, Ceres's glog) are found in the sysroot at link time.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-Wl,-rpath-link,${PATROLMAP_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu:${PATROLMAP_ARM64_SYSROOT}/lib/aarch64-linux-gnu")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "${CMAKE_EXE_LINKER_FLAGS_INIT}")
