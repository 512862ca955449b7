// The system calls the V4L2 sensor makes, behind one seam so the unit tests can stand a scripted
// device in for a kernel driver. Every call returns 0 (or a count) on success and -errno on
// failure, so the caller never reads errno after an intervening call.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lb {

class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int Open(const char* path, int flags) = 0;  // a file descriptor or -errno
  virtual int Close(int fd) = 0;
  // Retries EINTR itself.
  virtual int Ioctl(int fd, unsigned long request, void* arg) = 0;
  // 1 when `events` are pending (in *revents), 0 on timeout, -errno.
  virtual int Poll(int fd, short events, int timeout_ms, short* revents) = 0;
  virtual int Map(int fd, size_t length, uint32_t offset, void** addr) = 0;
  virtual int Unmap(void* addr, size_t length) = 0;
};

// The real kernel interface.
V4l2Io& SystemV4l2Io();

// strerror for a positive errno value, thread-safe; the text may be a static string instead of
// `buffer`. Named apart from firmware/storage's lb::ErrnoText, which takes the same arguments
// and returns nothing: under one name a program linking both got this one for every call that
// was not inlined, and printed that function's unfilled buffer.
const char* V4l2ErrnoText(int err, char* buffer, size_t size);

}  // namespace lb
