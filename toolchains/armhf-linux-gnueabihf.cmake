# Cross build for 32-bit ARM boards (Debian armhf). Test binaries run under qemu-user.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR armv7l)
set(CMAKE_C_COMPILER arm-linux-gnueabihf-gcc)
set(CMAKE_CXX_COMPILER arm-linux-gnueabihf-g++)
# Target libraries come from a private sysroot made by scripts/cross-sysroot.sh armhf.
set(LB_SYSROOT ${CMAKE_CURRENT_LIST_DIR}/../build/sysroot/armhf)
set(CMAKE_FIND_ROOT_PATH /usr/arm-linux-gnueabihf ${LB_SYSROOT})
set(CMAKE_LIBRARY_ARCHITECTURE arm-linux-gnueabihf)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_LIBDIR} "${LB_SYSROOT}/usr/lib/arm-linux-gnueabihf/pkgconfig:${LB_SYSROOT}/usr/share/pkgconfig")
set(CMAKE_CROSSCOMPILING_EMULATOR
    qemu-arm-static;-L;/usr/arm-linux-gnueabihf;-E;LD_LIBRARY_PATH=${LB_SYSROOT}/usr/lib/arm-linux-gnueabihf:${LB_SYSROOT}/lib/arm-linux-gnueabihf)
# zlib lives in /lib/<triple>, the rest in /usr/lib/<triple>.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-Wl,-rpath-link,${LB_SYSROOT}/usr/lib/arm-linux-gnueabihf -Wl,-rpath-link,${LB_SYSROOT}/lib/arm-linux-gnueabihf")
# Debian puts architecture-specific headers (jconfig.h) under include/<triple>.
set(CMAKE_C_STANDARD_INCLUDE_DIRECTORIES ${LB_SYSROOT}/usr/include/arm-linux-gnueabihf)
set(CMAKE_CXX_STANDARD_INCLUDE_DIRECTORIES ${LB_SYSROOT}/usr/include/arm-linux-gnueabihf)
