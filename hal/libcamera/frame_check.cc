#include "hal/libcamera/frame_check.h"

#include "hal/libcamera/libcamera_version.h"

namespace lb {

bool IsStartupFrame(const libcamera::FrameMetadata& metadata) {
#if LB_LIBCAMERA_AT_LEAST(0, 5, 2)
  return metadata.status == libcamera::FrameMetadata::FrameStartup;
#else
  (void)metadata;
  return false;
#endif
}

FrameVerdict CheckFrame(const libcamera::FrameMetadata& metadata, int32_t delivered,
                        FrameSequence* sequence, uint32_t* missing) {
  *missing = 0;
  const bool startup = IsStartupFrame(metadata);
  if (!startup && metadata.status != libcamera::FrameMetadata::FrameSuccess) {
    return FrameVerdict::kFailed;
  }
  if (startup && delivered == 0) return FrameVerdict::kSkip;
  if (!sequence->Next(metadata.sequence, missing) || *missing > 0) return FrameVerdict::kDropped;
  return startup ? FrameVerdict::kSkip : FrameVerdict::kDeliver;
}

}  // namespace lb
