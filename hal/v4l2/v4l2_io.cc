#include "hal/v4l2/v4l2_io.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

namespace lb {
namespace {

class SystemIo : public V4l2Io {
 public:
  int Open(const char* path, int flags) override {
    int fd = ::open(path, flags);
    return fd >= 0 ? fd : -errno;
  }
  int Close(int fd) override { return ::close(fd) == 0 ? 0 : -errno; }
  int Ioctl(int fd, unsigned long request, void* arg) override {
    for (;;) {
      if (::ioctl(fd, request, arg) == 0) return 0;
      if (errno != EINTR) return -errno;
    }
  }
  int Poll(int fd, short events, int timeout_ms, short* revents) override {
    pollfd p = {fd, events, 0};
    int n = ::poll(&p, 1, timeout_ms);
    if (n < 0) return -errno;
    *revents = p.revents;
    return n;
  }
  int Map(int fd, size_t length, uint32_t offset, void** addr) override {
    // mmap64: the driver's cookie is a full 32-bit offset, beyond a 32-bit off_t on armhf.
    void* p = ::mmap64(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
    if (p == MAP_FAILED) return -errno;
    *addr = p;
    return 0;
  }
  int Unmap(void* addr, size_t length) override { return ::munmap(addr, length) == 0 ? 0 : -errno; }
};

}  // namespace

V4l2Io& SystemV4l2Io() {
  static SystemIo io;
  return io;
}

const char* V4l2ErrnoText(int err, char* buffer, size_t size) {
  // The GNU strerror_r may return a static string instead of filling the buffer.
  return strerror_r(err, buffer, size);
}

}  // namespace lb
