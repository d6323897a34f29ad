# arm64 (Raspberry Pi 4/5, Jetson CPU, RK3588) with Debian 12's g++-aarch64-linux-gnu; preset arm64.
set(AERIE_CROSS_TRIPLET aarch64-linux-gnu)
set(AERIE_CROSS_PROCESSOR aarch64)
set(AERIE_CROSS_QEMU qemu-aarch64-static)
set(AERIE_CROSS_SYSROOT_DEFAULT /opt/aerie-sysroot-arm64)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
