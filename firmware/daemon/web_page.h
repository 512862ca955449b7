// What refocusd gives its web page: the server's options from the configuration, and the
// renderer the page calls, sized for the camera's photos and yielding to the camera's captures.
// The web side declares both types (web_server.h, refocus_backend.h) and never sees the daemon.
#pragma once

#include <memory>

#include "firmware/daemon/camera_daemon.h"
#include "firmware/daemon/config.h"
#include "firmware/platform/log.h"
#include "firmware/web/refocus_backend.h"
#include "firmware/web/web_server.h"

namespace lb {

// The options the configuration implies (web must be on): its address, port, token and page
// files, and the output folder as the photo folder; every limit keeps the server's default.
WebServerOptions WebOptionsFrom(const DaemonConfig& config);

// EngineBackend (firmware/web/engine_backend.h), sized from the configuration's resolution and
// waiting while `daemon` takes a photo. `log` and `daemon` are borrowed and must outlive it.
std::unique_ptr<RefocusBackend> MakeRefocusBackend(const DaemonConfig& config, Log* log,
                                                   const CameraDaemon& daemon);

}  // namespace lb
