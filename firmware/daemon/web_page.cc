#include "firmware/daemon/web_page.h"

#include "firmware/web/engine_backend.h"

namespace lb {
namespace {

// The largest sensor the product is specified for (12 MP, 4056x3040). With `resolution = 0x0`
// (the sensor's native size, known only once it is configured) the renderer is sized for it; a
// larger photo in the folder is refused by the engine, not cropped.
constexpr int32_t kLargestWidth = 4056;
constexpr int32_t kLargestHeight = 3040;

}  // namespace

WebServerOptions WebOptionsFrom(const DaemonConfig& config) {
  WebServerOptions o;
  o.address = config.web_address;
  o.port = config.web_port;
  o.token = config.web_token;
  o.web_root = config.web_root;
  o.photo_dir = config.output_dir;
  return o;
}

std::unique_ptr<RefocusBackend> MakeRefocusBackend(const DaemonConfig& config, Log* log,
                                                   const CameraDaemon& daemon) {
  const SensorConfig& sensor = config.job.sensor;
  const bool sized = sensor.width > 0 && sensor.height > 0;
  return std::make_unique<EngineBackend>(sized ? sensor.width : kLargestWidth,
                                         sized ? sensor.height : kLargestHeight, config.job.threads,
                                         log, daemon.camera_busy());
}

}  // namespace lb
