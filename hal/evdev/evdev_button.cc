#include "hal/evdev/evdev_button.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

namespace lb {
namespace {

int64_t MonotonicMs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000;
}

bool TestBit(const uint8_t* bits, int bit) { return (bits[bit / 8] >> (bit % 8)) & 1; }

}  // namespace

Status EvdevButton::Open(const char* path) {
  Close();
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    int err = errno;
    char text[96];
    return Status(err == ENOENT ? Code::kNotFound : Code::kIoError,
                  "%s: cannot open: %s (errno %d)", path, strerror_r(err, text, sizeof(text)), err);
  }
  uint8_t keys[KEY_MAX / 8 + 1] = {};
  if (ioctl(fd, EVIOCGBIT(EV_KEY, sizeof(keys)), keys) < 0) {
    int err = errno;
    close(fd);
    char text[96];
    return Status(Code::kUnsupported, "%s: not an input device: EVIOCGBIT failed: %s (errno %d)",
                  path, strerror_r(err, text, sizeof(text)), err);
  }
  if (!TestBit(keys, KEY_CAMERA)) {
    char device_name[64] = "?";
    (void)ioctl(fd, EVIOCGNAME(sizeof(device_name) - 1), device_name);
    close(fd);
    return Status(Code::kUnsupported, "%s (%s): the device cannot send KEY_CAMERA", path,
                  device_name);
  }
  Adopt(fd, path);
  return Status::Ok();
}

void EvdevButton::Adopt(int fd, const char* name) {
  Close();
  fd_ = fd;
  snprintf(name_, sizeof(name_), "%s", name);
}

void EvdevButton::Close() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  camera_ = Key();
  focus_ = Key();
  dropping_ = false;
  partial_bytes_ = 0;
  head_ = count_ = 0;
}

void EvdevButton::Push(ButtonEvent event) {
  // Reads are sized so the queue cannot overflow (kReadEvents <= kMaxPending).
  if (count_ == kMaxPending) return;
  pending_[(head_ + count_) % kMaxPending] = event;
  ++count_;
}

void EvdevButton::OnKey(Key& key, bool down, int64_t now_us, ButtonEvent press,
                        bool report_release) {
  bool quiet = !key.seen || now_us - key.last_us >= int64_t{debounce_ms_} * 1000;
  key.seen = true;
  key.last_us = now_us;
  if (down && !key.down && quiet) {
    key.down = true;
    Push(press);
  } else if (!down && key.down) {
    key.down = false;
    if (report_release) Push(ButtonEvent::kRelease);
  }
}

void EvdevButton::Resync(int64_t now_us) {
  uint8_t keys[KEY_MAX / 8 + 1] = {};
  if (ioctl(fd_, EVIOCGKEY(sizeof(keys)), keys) < 0) return;  // not a device (a test pipe)
  // Only a change against what was reported counts, so the debounce window does not apply.
  bool camera = TestBit(keys, KEY_CAMERA);
  if (camera != camera_.down) {
    camera_.seen = false;
    OnKey(camera_, camera, now_us, ButtonEvent::kPress, true);
  }
  bool focus = TestBit(keys, KEY_CAMERA_FOCUS);
  if (focus != focus_.down) {
    focus_.seen = false;
    OnKey(focus_, focus, now_us, ButtonEvent::kHalfPress, false);
  }
}

void EvdevButton::Feed(const input_event& ev) {
  int64_t now_us = static_cast<int64_t>(ev.input_event_sec) * 1000000 +
                   static_cast<int64_t>(ev.input_event_usec);
  if (ev.type == EV_SYN) {
    if (ev.code == SYN_DROPPED) {
      dropping_ = true;
    } else if (ev.code == SYN_REPORT && dropping_) {
      dropping_ = false;
      Resync(now_us);
    }
    return;
  }
  if (dropping_ || ev.type != EV_KEY || ev.value == 2) return;
  bool down = ev.value != 0;
  if (ev.code == KEY_CAMERA) {
    OnKey(camera_, down, now_us, ButtonEvent::kPress, true);
  } else if (ev.code == KEY_CAMERA_FOCUS) {
    OnKey(focus_, down, now_us, ButtonEvent::kHalfPress, false);
  }
}

Status EvdevButton::Wait(int32_t timeout_ms, ButtonEvent* event) {
  *event = ButtonEvent::kNone;
  if (fd_ < 0) return Status(Code::kInvalidArgument, "button: Wait before Open");
  int64_t deadline = timeout_ms < 0 ? -1 : MonotonicMs() + timeout_ms;
  char text[96];
  while (count_ == 0) {
    int wait = -1;
    if (deadline >= 0) {
      int64_t left = deadline - MonotonicMs();
      wait = left > 0 ? static_cast<int>(left) : 0;
    }
    pollfd p = {fd_, POLLIN, 0};
    int n = poll(&p, 1, wait);
    if (n < 0) {
      if (errno == EINTR) continue;
      int err = errno;
      return Status(Code::kIoError, "%s: poll failed: %s (errno %d)", name_,
                    strerror_r(err, text, sizeof(text)), err);
    }
    if (n == 0) return Status::Ok();  // timed out: kNone
    uint8_t bytes[kReadEvents * sizeof(input_event)];
    memcpy(bytes, partial_, partial_bytes_);
    ssize_t got = read(fd_, bytes + partial_bytes_, sizeof(bytes) - partial_bytes_);
    if (got < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      int err = errno;
      return Status(err == ENODEV ? Code::kNotFound : Code::kIoError,
                    "%s: read failed: %s (errno %d)", name_, strerror_r(err, text, sizeof(text)),
                    err);
    }
    if (got == 0) return Status(Code::kNotFound, "%s: the input device went away", name_);
    size_t total = partial_bytes_ + static_cast<size_t>(got);
    size_t whole = total / sizeof(input_event);
    for (size_t i = 0; i < whole; ++i) {
      input_event ev;
      memcpy(&ev, bytes + i * sizeof(input_event), sizeof(ev));
      Feed(ev);
    }
    partial_bytes_ = total - whole * sizeof(input_event);
    memcpy(partial_, bytes + whole * sizeof(input_event), partial_bytes_);
  }
  *event = pending_[head_];
  head_ = (head_ + 1) % kMaxPending;
  --count_;
  return Status::Ok();
}

Status EvdevButton::FindCameraButton(char* path, size_t size) {
  for (int i = 0; i < 64; ++i) {
    char candidate[32];
    snprintf(candidate, sizeof(candidate), "/dev/input/event%d", i);
    int fd = open(candidate, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) continue;
    uint8_t keys[KEY_MAX / 8 + 1] = {};
    bool camera =
        ioctl(fd, EVIOCGBIT(EV_KEY, sizeof(keys)), keys) >= 0 && TestBit(keys, KEY_CAMERA);
    close(fd);
    if (camera) {
      snprintf(path, size, "%s", candidate);
      return Status::Ok();
    }
  }
  return Status(Code::kNotFound, "no /dev/input/event* device sends KEY_CAMERA");
}

}  // namespace lb
