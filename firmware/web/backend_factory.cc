// The renderer refocusd gives its web page. Until the fixed-memory engine (engine_backend.h,
// class EngineBackend) is merged, a stand-in that answers kUnsupported: the gallery,
// thumbnails and downloads work and the page says refocusing is not available yet. Once merged
// this file returns std::make_unique<EngineBackend>(config, log, daemon).
#include "firmware/web/web_server.h"

namespace lb {
namespace {

class UnavailableBackend final : public RefocusBackend {
 public:
  Status Describe(const char*, PhotoInfo*) override { return Unavailable(); }
  Status Render(const char*, const RefocusParams&, bool, ByteSink*) override {
    return Unavailable();
  }
  Status Save(const char*, const RefocusParams&, const char*) override { return Unavailable(); }

 private:
  static Status Unavailable() {
    return Status(Code::kUnsupported, "refocusing from the page is not in this build yet");
  }
};

}  // namespace

std::unique_ptr<RefocusBackend> MakeRefocusBackend(const DaemonConfig& /*config*/, Log* /*log*/,
                                                   CameraDaemon* /*daemon*/) {
  return std::make_unique<UnavailableBackend>();
}

}  // namespace lb
