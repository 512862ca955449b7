# Cross build for 64-bit ARM boards (Debian arm64). Test binaries run under qemu-user.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# Target libraries come from a private sysroot made by scripts/cross-sysroot.sh arm64.
set(LB_SYSROOT ${CMAKE_CURRENT_LIST_DIR}/../build/sysroot/arm64)
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu ${LB_SYSROOT})
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_LIBDIR} "${LB_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${LB_SYSROOT}/usr/share/pkgconfig")
set(CMAKE_CROSSCOMPILING_EMULATOR
    qemu-aarch64-static;-L;/usr/aarch64-linux-gnu;-E;LD_LIBRARY_PATH=${LB_SYSROOT}/usr/lib/aarch64-linux-gnu:${LB_SYSROOT}/lib/aarch64-linux-gnu)
# zlib lives in /lib/<triple>, the rest in /usr/lib/<triple>.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-Wl,-rpath-link,${LB_SYSROOT}/usr/lib/aarch64-linux-gnu -Wl,-rpath-link,${LB_SYSROOT}/lib/aarch64-linux-gnu")
# Debian puts architecture-specific headers (jconfig.h) under include/<triple>.
set(CMAKE_C_STANDARD_INCLUDE_DIRECTORIES ${LB_SYSROOT}/usr/include/aarch64-linux-gnu)
set(CMAKE_CXX_STANDARD_INCLUDE_DIRECTORIES ${LB_SYSROOT}/usr/include/aarch64-linux-gnu)
