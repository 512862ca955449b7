// The rule every file the product writes goes through, checked before any work starts (and by
// AtomicFile again at the rename): the target is absent or a regular file, never a device, a
// FIFO, a folder or a symbolic link, which the rename would replace; its folder exists and can
// be written to; and it is none of the run's inputs (nor the same file under another name).
#pragma once

#include <cstdint>

#include "algo/core/status.h"

namespace lb {

// kInvalidArgument for a target that may not be written, kNotFound or kIoError for a folder
// that is missing or read-only. `inputs` may be null when `input_count` is 0.
Status CheckOutputTarget(const char* path, const char* const* inputs, int32_t input_count);

// The part AtomicFile repeats just before its rename: absent or a regular file.
Status CheckTargetKind(const char* path);

}  // namespace lb
