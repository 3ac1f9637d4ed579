# SPDX-License-Identifier: Apache-2.0
# Cross build for arm64 (aarch64) with Debian's cross compiler (crossbuild-essential-arm64) against
# a sysroot holding Debian 12's arm64 -dev packages (scripts/arm64 makes and caches one):
#   cmake -S . -B build-arm64 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-arm64.cmake \
#         -DFUSEDET_ARM64_SYSROOT=/path/to/sysroot
# Programs built here run under qemu-user (qemu-user-static) as CMake's cross-compiling emulator.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
if(NOT FUSEDET_ARM64_SYSROOT)
  set(FUSEDET_ARM64_SYSROOT "$ENV{FUSEDET_ARM64_SYSROOT}")
endif()
if(NOT IS_DIRECTORY "${FUSEDET_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu")
  message(FATAL_ERROR "FUSEDET_ARM64_SYSROOT='${FUSEDET_ARM64_SYSROOT}' is not an arm64 sysroot (scripts/arm64 makes one)")
endif()
# try_compile projects get their own copy of this file: hand them the sysroot too.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES FUSEDET_ARM64_SYSROOT)
set(CMAKE_SYSROOT "${FUSEDET_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH "${FUSEDET_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${FUSEDET_ARM64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR} "${FUSEDET_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${FUSEDET_ARM64_SYSROOT}/usr/share/pkgconfig")
set(CMAKE_CROSSCOMPILING_EMULATOR /usr/bin/qemu-aarch64-static -L "${FUSEDET_ARM64_SYSROOT}")
