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

# Written by hand: dpkg-shlibdeps needs the target's libraries installed as packages, which a
# cross sysroot is not. tests/firmware/daemon/check_deb.sh checks every library the binaries
# link is covered. Bookworm's versions.
set(lb_deb_depends "libc6 (>= 2.36), libgcc-s1 (>= 3.0), libstdc++6 (>= 12)"
    "libjpeg62-turbo (>= 1:2.1)" "libpng16-16 (>= 1.6.2)" "libexif12 (>= 0.6.21)"
    "libmd0 (>= 1.0)" "libmicrohttpd12 (>= 0.9.75)")
if(TARGET lb_libcamera)
  list(APPEND lb_deb_depends "libcamera0.0.3")
endif()
string(JOIN ", " CPACK_DEBIAN_PACKAGE_DEPENDS ${lb_deb_depends})

set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${CMAKE_CURRENT_SOURCE_DIR}/deb/conffiles ${CMAKE_CURRENT_SOURCE_DIR}/deb/postinst
    ${CMAKE_CURRENT_SOURCE_DIR}/deb/prerm ${CMAKE_CURRENT_SOURCE_DIR}/deb/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
include(CPack)
