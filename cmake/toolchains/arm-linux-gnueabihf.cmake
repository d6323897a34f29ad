# armhf (32-bit ARMv7 + VFPv3-D16, hard float: Debian's armhf baseline, e.g. the ODROID U3's
# Cortex-A9) with Debian 12's g++-arm-linux-gnueabihf; preset armhf.
set(AERIE_CROSS_TRIPLET arm-linux-gnueabihf)
set(AERIE_CROSS_PROCESSOR armv7l)
set(AERIE_CROSS_QEMU qemu-arm-static)
set(AERIE_CROSS_SYSROOT_DEFAULT /opt/aerie-sysroot-armhf)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
