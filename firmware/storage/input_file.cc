#include "firmware/storage/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "firmware/storage/errno_text.h"

namespace lb {
namespace {

const char* KindOf(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

}  // namespace

Status OpenInputFile(const char* path, int* fd, int64_t* size, int extra_flags) {
  *fd = -1;
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer, with no word.
  const int got = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | extra_flags);
  if (got < 0) {
    const int err = errno;
    if (err == ENOENT) return Status(Code::kNotFound, "%s: no such file or directory", path);
    char text[128];
    ErrnoText(err, text, sizeof(text));
    return Status(Code::kIoError, "%s: cannot open: %s", path, text);
  }
  struct stat st;
  if (fstat(got, &st) != 0) {
    const int err = errno;
    close(got);
    char text[128];
    ErrnoText(err, text, sizeof(text));
    return Status(Code::kIoError, "%s: cannot read: %s", path, text);
  }
  if (!S_ISREG(st.st_mode)) {
    close(got);
    return Status(Code::kInvalidArgument, "%s: not a regular file (%s): name an image file", path,
                  KindOf(st.st_mode));
  }
  // Reads block again, as every reader expects (a file on a slow card is no FIFO).
  const int flags = fcntl(got, F_GETFL);
  if (flags < 0 || fcntl(got, F_SETFL, flags & ~O_NONBLOCK) != 0) {
    const int err = errno;
    close(got);
    char text[128];
    ErrnoText(err, text, sizeof(text));
    return Status(Code::kIoError, "%s: cannot read: %s", path, text);
  }
  *fd = got;
  if (size != nullptr) *size = static_cast<int64_t>(st.st_size);
  return Status::Ok();
}

Status ReadInputFile(const char* path, size_t max_bytes, std::vector<uint8_t>* bytes) {
  bytes->clear();
  int fd = -1;
  int64_t size = 0;
  LB_RETURN_IF_ERROR(OpenInputFile(path, &fd, &size));
  if (static_cast<uint64_t>(size) > max_bytes) {
    close(fd);
    return Status(Code::kInvalidArgument, "%s: %lld bytes, over the %zu MiB taken", path,
                  static_cast<long long>(size), max_bytes >> 20);
  }
  bytes->resize(static_cast<size_t>(size));
  size_t done = 0;
  while (done < bytes->size()) {
    const ssize_t n = read(fd, bytes->data() + done, bytes->size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      close(fd);
      bytes->clear();
      char text[128];
      ErrnoText(err, text, sizeof(text));
      return Status(Code::kIoError, "%s: read error: %s", path, text);
    }
    if (n == 0) break;  // shorter than when it was opened: what is there is read
    done += static_cast<size_t>(n);
  }
  close(fd);
  bytes->resize(done);
  return Status::Ok();
}

}  // namespace lb
