# `cpack -G DEB` (or the `package` target) in a build tree makes the board's Debian package:
# refocusd and refocus in /usr/bin, the systemd unit in /lib/systemd/system and the default
# configuration as the conffile /etc/refocusd.conf (local edits survive upgrades), and the web
# page's files in /usr/share/refocusd/www (firmware/web/CMakeLists.txt).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME refocusd)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "Lens blur firmware <firmware@lensblur.invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "lens-blur camera daemon: shutter button to refocused JPEG")
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "Captures a short burst at each press of the shutter button, computes a depth map by graph\n\
cuts, renders a synthetic shallow depth of field and writes the JPEG. Holds the daemon\n\
refocusd (a systemd service) and the command line tool refocus.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_STRIP_FILES ON)

# The target's Debian architecture (cpack would otherwise take the build machine's).
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^arm")
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE armhf)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64)$")
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE amd64)
endif()

# The release the package is built for: its version says so (0.1.0+deb12, 0.1.0+deb13), since
# each release's package links that release's libraries (libcamera's soname differs in each).
set(LB_DEB_RELEASE "" CACHE STRING "Debian release the package is built against (deb12, deb13)")
if(LB_DEB_RELEASE)
  set(CPACK_DEBIAN_PACKAGE_VERSION ${PROJECT_VERSION}+${LB_DEB_RELEASE})
endif()
# dpkg-shlibdeps states the dependencies from the libraries the programs link, as the release's
# packages declare them. It needs those libraries installed as packages: a native build, or a
# cross build against multiarch packages (scripts/package.sh). A cross build against the private
# sysroot of the unit tests makes no package.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Cameras behind an ISP (Raspberry Pi, Rockchip, Intel IPU3) need libcamera's image-processing
# modules; Debian 12's libcamera only suggests them.
if(TARGET lb_libcamera)
  set(CPACK_DEBIAN_PACKAGE_RECOMMENDS libcamera-ipa)
endif()
if(CMAKE_CROSSCOMPILING AND NOT LB_MULTIARCH)
  return()
endif()

set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${CMAKE_CURRENT_SOURCE_DIR}/deb/conffiles ${CMAKE_CURRENT_SOURCE_DIR}/deb/postinst
    ${CMAKE_CURRENT_SOURCE_DIR}/deb/prerm ${CMAKE_CURRENT_SOURCE_DIR}/deb/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
include(CPack)
