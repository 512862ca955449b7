// The one place the libcamera backend learns which libcamera it is built against: the version
// libcamera's own header declares. libcamera's API changes between minor releases (0.x), so code
// paths are chosen with LB_LIBCAMERA_AT_LEAST, never by probing for symbols.
#pragma once

#include <libcamera/version.h>

// True when the libcamera headers in use are major.minor.patch or newer.
#define LB_LIBCAMERA_AT_LEAST(major, minor, patch)                                                 \
  (LIBCAMERA_VERSION_MAJOR * 1000000 + LIBCAMERA_VERSION_MINOR * 1000 + LIBCAMERA_VERSION_PATCH >= \
   (major)*1000000 + (minor)*1000 + (patch))
