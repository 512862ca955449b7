// The one way the product opens a file it reads (a burst's frames, a view, a refocusable JPEG):
// a FIFO, a device, a socket or a folder under an input's name is refused at once with a line
// naming it, where a plain open would wait for a writer that never comes, or read a device.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/status.h"

namespace lb {

// Opens `path` read-only and close-on-exec (plus `extra_flags`, e.g. O_NOFOLLOW) and fstats it:
// `*fd` is a blocking descriptor of a regular file, `*size` (may be null) its length. kNotFound
// for a missing file, kInvalidArgument naming the kind for anything but a regular file, kIoError
// otherwise; `*fd` is -1 on failure.
Status OpenInputFile(const char* path, int* fd, int64_t* size = nullptr, int extra_flags = 0);

// The whole file, refused (kInvalidArgument) when it is over `max_bytes`.
Status ReadInputFile(const char* path, size_t max_bytes, std::vector<uint8_t>* bytes);

}  // namespace lb
