# Shared part of the Debian 12 cross toolchains (aarch64-linux-gnu.cmake, arm-linux-gnueabihf.cmake;
# docs/arm.md). The including file sets AERIE_CROSS_TRIPLET (GNU triplet = Debian multiarch dir),
# AERIE_CROSS_PROCESSOR, AERIE_CROSS_QEMU (qemu-user binary name) and AERIE_CROSS_SYSROOT_DEFAULT.
#
# Compilers: Debian's g++-<triplet> cross packages. Target libraries: a Debian sysroot made by
# scripts/arm.sh with mmdebstrap (path: -DAERIE_SYSROOT=..., else $AERIE_SYSROOT, else the default).
# Host programs (lcm-gen, python3, java) are found on the host; libraries, headers and CMake
# packages only in the sysroot. Tests run under qemu-user (CMAKE_CROSSCOMPILING_EMULATOR).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR ${AERIE_CROSS_PROCESSOR})

if(NOT AERIE_SYSROOT)
  if(DEFINED ENV{AERIE_SYSROOT})
    set(AERIE_SYSROOT "$ENV{AERIE_SYSROOT}")
  else()
    set(AERIE_SYSROOT "${AERIE_CROSS_SYSROOT_DEFAULT}")
  endif()
endif()
set(AERIE_SYSROOT "${AERIE_SYSROOT}" CACHE PATH "Debian ${AERIE_CROSS_TRIPLET} sysroot (scripts/arm.sh makes it)")
if(NOT EXISTS "${AERIE_SYSROOT}/usr/lib/${AERIE_CROSS_TRIPLET}")
  message(FATAL_ERROR "No ${AERIE_CROSS_TRIPLET} sysroot at ${AERIE_SYSROOT}: run scripts/arm.sh "
                      "(or set AERIE_SYSROOT to a Debian 12 sysroot with the air side's -dev packages)")
endif()
# try_compile projects re-read this file: pass the resolved path on to them.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES AERIE_SYSROOT)

set(CMAKE_SYSROOT "${AERIE_SYSROOT}")
set(CMAKE_C_COMPILER   ${AERIE_CROSS_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${AERIE_CROSS_TRIPLET}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${AERIE_CROSS_TRIPLET})

set(CMAKE_FIND_ROOT_PATH "${AERIE_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)   # lcm-gen, python3, javac: the host's
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config (LCM, Highway, glib) reads the sysroot's .pc files and prefixes their paths.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${AERIE_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${AERIE_SYSROOT}/usr/lib/${AERIE_CROSS_TRIPLET}/pkgconfig:${AERIE_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# Tests (and gtest discovery) run under qemu-user with the sysroot as the dynamic loader's root.
# QEMU_LD_PREFIX also reaches the target programs a test starts itself (aerie-deputy, aerie-link,
# aerie-sim): those run through binfmt_misc, which scripts/arm.sh enables when it can.
find_program(AERIE_QEMU ${AERIE_CROSS_QEMU} REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR /usr/bin/env "QEMU_LD_PREFIX=${AERIE_SYSROOT}" ${AERIE_QEMU} -L "${AERIE_SYSROOT}")
