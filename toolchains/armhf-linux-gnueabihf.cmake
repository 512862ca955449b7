# Cross build for 32-bit ARM boards (Debian armhf: ARMv7-A with VFPv3-D16; NEON is optional).
set(CMAKE_SYSTEM_PROCESSOR armv7l)
set(LB_TRIPLE arm-linux-gnueabihf)
set(LB_DEB_ARCH armhf)
set(LB_QEMU qemu-arm-static)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
