# What every cross build for a Debian ARM board shares; the including file sets
#   LB_TRIPLE (GNU triple), LB_DEB_ARCH (Debian architecture), LB_QEMU (qemu-user binary) and
#   CMAKE_SYSTEM_PROCESSOR.
# Target libraries come from one of two places:
#   - a private sysroot made by scripts/cross-sysroot.sh LB_DEB_ARCH (the default: the host's
#     unit-test builds, whose test programs run under qemu-user);
#   - with -DLB_MULTIARCH=ON, the machine's own multiarch packages (libfoo-dev:LB_DEB_ARCH
#     installed by apt in a Debian root of the target release, as scripts/package.sh makes), so
#     dpkg-shlibdeps can state the package's dependencies.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_C_COMPILER ${LB_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${LB_TRIPLE}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${LB_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# try_compile projects read this file again: they must take the same branch.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES LB_MULTIARCH)
if(LB_MULTIARCH)
  set(CMAKE_FIND_ROOT_PATH /)
  set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/${LB_TRIPLE}/pkgconfig:/usr/share/pkgconfig")
  set(CMAKE_CROSSCOMPILING_EMULATOR ${LB_QEMU};-L;/)
  return()
endif()
set(LB_SYSROOT ${CMAKE_CURRENT_LIST_DIR}/../build/sysroot/${LB_DEB_ARCH})
set(CMAKE_FIND_ROOT_PATH /usr/${LB_TRIPLE} ${LB_SYSROOT})
set(ENV{PKG_CONFIG_LIBDIR} "${LB_SYSROOT}/usr/lib/${LB_TRIPLE}/pkgconfig:${LB_SYSROOT}/usr/share/pkgconfig")
set(CMAKE_CROSSCOMPILING_EMULATOR
    ${LB_QEMU};-L;/usr/${LB_TRIPLE};-E;LD_LIBRARY_PATH=${LB_SYSROOT}/usr/lib/${LB_TRIPLE}:${LB_SYSROOT}/lib/${LB_TRIPLE})
# zlib lives in /lib/<triple>, the rest in /usr/lib/<triple>.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-Wl,-rpath-link,${LB_SYSROOT}/usr/lib/${LB_TRIPLE} -Wl,-rpath-link,${LB_SYSROOT}/lib/${LB_TRIPLE}")
# Debian puts architecture-specific headers (jconfig.h) under include/<triple>.
set(CMAKE_C_STANDARD_INCLUDE_DIRECTORIES ${LB_SYSROOT}/usr/include/${LB_TRIPLE})
set(CMAKE_CXX_STANDARD_INCLUDE_DIRECTORIES ${LB_SYSROOT}/usr/include/${LB_TRIPLE})
