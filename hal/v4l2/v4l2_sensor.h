// V4L2 sensor: a single-planar capture node streamed through mmap'ed driver buffers. Configure
// opens the node, negotiates the format and maps the buffers (the slow part, so a half press can
// run it early); CaptureBurst streams, hands each frame to the sink, and stops streaming again.
// YUYV, NV12, RGB24 and BGR24 frames go to the sink as one strip straight from their driver
// buffer. MJPEG (or JPEG) frames, which most USB cameras send at 720p and up, are decoded to RGB8
// strips of a few rows (mjpeg_decoder.h); the sensor takes them when the device offers nothing
// uncompressed at the wanted size, or when V4l2Options::fourcc asks for them.
//
// Dropped frames (a gap in the buffer sequence numbers or a buffer the driver flags bad) fail the
// burst: the caller retries with a fresh burst. A corrupt MJPEG frame (empty, cut short, garbage,
// another size than the mode) found before any of its rows reached the sink is skipped instead:
// one log line, and the next frame takes its place, so the burst's views are one frame time
// further apart there (FrameInfo::sequence shows it; the pipeline's auto geometry measures each
// view's pose). More than max_corrupt_frames of them fail the burst. Damage libjpeg finds only
// after rows went to the sink fails the burst, as the sink cannot take a frame back.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/frame_sequence.h"
#include "hal/sensor.h"
#include "hal/v4l2/mjpeg_decoder.h"
#include "hal/v4l2/v4l2_format.h"
#include "hal/v4l2/v4l2_io.h"

namespace lb {

struct V4l2Options {
  static constexpr int32_t kMaxBuffers = 8;
  const char* device = "/dev/video0";  // copied by the constructor
  // 0: uncompressed if offered at the wanted size, else MJPEG (ChooseFourcc in v4l2_format.h).
  uint32_t fourcc = 0;
  // Driver buffers to request, 2..kMaxBuffers; 0: one per burst frame, so a slow consumer never
  // leaves the driver without a buffer (which it reports as a dropped frame).
  int32_t buffers = 0;
  // Frames per second to ask for (VIDIOC_S_PARM), 0 = the driver's choice. A rate the device
  // cannot keep shows up as dropped frames, so a slow sensor wants a modest rate here.
  int32_t fps = 0;
  // Corrupt MJPEG frames a burst skips before it fails, 0..kMaxFrames.
  int32_t max_corrupt_frames = 3;
  // Told what the sensor gets past without failing (a corrupt frame skipped): one line, no
  // newline, called on the capturing thread during the burst; must not allocate. nullptr: not
  // told (corrupt_frames() still counts).
  void (*log)(void* context, const char* line) = nullptr;
  void* log_context = nullptr;
};

class V4l2Sensor : public Sensor {
 public:
  static constexpr int32_t kMaxFrames = 64;

  // `io` is borrowed (tests pass a scripted device); nullptr means the real system calls.
  explicit V4l2Sensor(const V4l2Options& options, V4l2Io* io = nullptr);
  ~V4l2Sensor() override;
  V4l2Sensor(const V4l2Sensor&) = delete;
  V4l2Sensor& operator=(const V4l2Sensor&) = delete;

  const char* name() const override { return "v4l2"; }
  // Opens the node, asks VIDIOC_QUERYCAP and closes it again (V4L2 allows several opens, so this
  // works while another process streams): kNotFound when nothing is at the path, kUnsupported
  // for a file or device that is no single-planar streaming capture node (the message says what
  // it is: not a V4L2 device, an output, a memory-to-memory device, a metadata node ...).
  Status Probe() override;
  Status Configure(const SensorConfig& config, SensorMode* mode) override;
  Status CaptureBurst(FrameSink& sink) override;
  void Stop() override;

  const V4l2Layout& layout() const { return layout_; }
  uint32_t fourcc() const { return fourcc_; }
  int32_t buffer_count() const { return buffer_count_; }
  // Corrupt MJPEG frames the last burst skipped.
  int32_t corrupt_frames() const { return corrupt_frames_; }
  const MjpegDecoder& decoder() const { return decoder_; }

 private:
  struct Buffer {
    void* addr = nullptr;
    size_t length = 0;
  };

  Status IoctlError(const char* what, int err) const;
  // Why a node with these QUERYCAP answers cannot be streamed, or Ok.
  Status CheckCaps(const v4l2_capability& cap) const;
  Status OpenAndNegotiate(const SensorConfig& config);
  // Whether the driver lists `fourcc` at width x height (VIDIOC_ENUM_FRAMESIZES); true when it
  // does not say.
  bool OffersSize(uint32_t fourcc, uint32_t width, uint32_t height);
  Status SetFrameRate();
  Status MapBuffers();
  Status QueueBuffer(uint32_t index);
  Status WaitFrame();
  Status Stream(FrameSink& sink);
  FrameInfo Info(const v4l2_buffer& buf, int32_t index) const;
  Status Deliver(FrameSink& sink, const v4l2_buffer& buf, int32_t index);
  // A frame it skips leaves *delivered false.
  Status DeliverMjpeg(FrameSink& sink, const v4l2_buffer& buf, int32_t index, bool* delivered);

  V4l2Io* io_;
  char device_[128] = {};
  uint32_t wanted_fourcc_ = 0;
  int32_t wanted_buffers_ = 0;
  int32_t wanted_fps_ = 0;
  int32_t max_corrupt_ = 0;
  void (*log_)(void*, const char*) = nullptr;
  void* log_context_ = nullptr;

  int fd_ = -1;
  SensorConfig config_;
  uint32_t fourcc_ = 0;
  V4l2Layout layout_;
  Buffer buffers_[V4l2Options::kMaxBuffers];
  int32_t buffer_count_ = 0;
  bool streaming_ = false;
  FrameSequence sequence_;
  MjpegDecoder decoder_;
  int32_t corrupt_frames_ = 0;
};

}  // namespace lb
