// What the burst does with a completed frame, from the metadata libcamera gives its buffer.
// From libcamera 0.5.2 a pipeline marks the frames it delivers while its algorithms converge
// after Camera::start (FrameMetadata::FrameStartup): they are skipped, not failures, and the
// dropped-frame check starts after them.
#pragma once

#include <libcamera/framebuffer.h>

#include <cstdint>

#include "hal/frame_sequence.h"

namespace lb {

enum class FrameVerdict : uint8_t {
  kDeliver,  // a good frame, next in sequence: into the burst
  kSkip,     // a startup frame: requeue its request and wait for the next
  kFailed,   // the pipeline marked it failed or cancelled: the burst is abandoned
  kDropped,  // frames are missing before it (*missing of them): the burst is abandoned
};

// At most this many startup frames are skipped in a row before the burst gives up: a pipeline
// converges within a few, and a camera that never settles must not hold the shutter forever.
inline constexpr int32_t kMaxStartupFrames = 60;

bool IsStartupFrame(const libcamera::FrameMetadata& metadata);

// `delivered`: frames of this burst already delivered. The sequence check sees every frame after
// the first delivered one, startup frames included (they are not drops), and none before it.
FrameVerdict CheckFrame(const libcamera::FrameMetadata& metadata, int32_t delivered,
                        FrameSequence* sequence, uint32_t* missing);

}  // namespace lb
