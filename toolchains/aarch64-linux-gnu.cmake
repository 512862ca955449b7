# Cross build for 64-bit ARM boards (Debian arm64).
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(LB_TRIPLE aarch64-linux-gnu)
set(LB_DEB_ARCH arm64)
set(LB_QEMU qemu-aarch64-static)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
