// Status: the error type of the whole product. No exceptions on the capture and processing path;
// every fallible call returns a [[nodiscard]] Status. The message lives inline (no heap) so a
// status can be made inside the no-allocation window and still name the file and the problem.
#pragma once

#include <cstdarg>
#include <cstddef>
#include <cstdint>

namespace lb {

enum class Code : uint8_t {
  kOk = 0,
  kInvalidArgument,  // the caller asked for something the configuration does not allow
  kOutOfMemory,      // an arena or fixed-capacity buffer is too small
  kCorruptData,      // input bytes that do not decode
  kIoError,          // the OS refused a read, write or ioctl
  kNotFound,         // a path, device or frame that is not there
  kUnsupported,      // a valid input this build cannot handle
  kTimeout,          // a device that stopped answering
  kBusy,             // asked while another operation is in progress
  kDegenerate,       // input that is valid but cannot give a useful result (e.g. no parallax)
  kInternal,         // a broken invariant: a bug
};

class [[nodiscard]] Status {
 public:
  static constexpr size_t kMaxMessage = 240;

  Status() = default;
  // printf-style message; truncated to kMaxMessage - 1 characters.
  Status(Code code, const char* format, ...) __attribute__((format(printf, 3, 4)));

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == Code::kOk; }
  Code code() const { return code_; }
  const char* message() const { return message_; }

  // Prefixes the message with context ("frame 3: " + message), keeping the code.
  Status& Prefix(const char* format, ...) __attribute__((format(printf, 2, 3)));

 private:
  Code code_ = Code::kOk;
  char message_[kMaxMessage] = {};
};

}  // namespace lb

// Returns early from the enclosing function when a status is not ok.
#define LB_RETURN_IF_ERROR(expr)             \
  do {                                       \
    ::lb::Status lb_status_ = (expr);        \
    if (!lb_status_.ok()) return lb_status_; \
  } while (0)
