// The renderer refocusd gives its web page: EngineBackend, sized at start for the camera's photos.
// With `resolution = 0x0` (the sensor's native size, known only once it is configured) it is
// sized for kLargestPhoto; a larger photo in the folder is refused by the engine, not cropped.
#include "firmware/daemon/camera_daemon.h"
#include "firmware/web/engine_backend.h"
#include "firmware/web/web_server.h"

namespace lb {
namespace {

// The largest sensor the product is specified for (12 MP, 4056x3040).
constexpr int32_t kLargestWidth = 4056;
constexpr int32_t kLargestHeight = 3040;

}  // namespace

std::unique_ptr<RefocusBackend> MakeRefocusBackend(const DaemonConfig& config, Log* log,
                                                   CameraDaemon* daemon) {
  const SensorConfig& sensor = config.job.sensor;
  const bool sized = sensor.width > 0 && sensor.height > 0;
  return std::make_unique<EngineBackend>(sized ? sensor.width : kLargestWidth,
                                         sized ? sensor.height : kLargestHeight, config.job.threads,
                                         log, daemon->camera_busy());
}

}  // namespace lb
