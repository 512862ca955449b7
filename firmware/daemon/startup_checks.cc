#include "firmware/daemon/startup_checks.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/daemon/photo_namer.h"
#include "firmware/storage/errno_text.h"

namespace lb {
namespace {

const char* FileKind(mode_t mode) {
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a folder";
}

}  // namespace

Status CheckPhotoFolder(const char* dir) {
  char text[96];
  struct stat st;
  if (stat(dir, &st) != 0) {
    const int err = errno;
    ErrnoText(err, text, sizeof(text));
    return Status(err == ENOENT || err == ENOTDIR ? Code::kNotFound : Code::kIoError,
                  "output folder %s: %s", dir, text);
  }
  if (!S_ISDIR(st.st_mode)) {
    return Status(Code::kNotFound, "output folder %s: not a folder (%s)", dir,
                  FileKind(st.st_mode));
  }
  // The limit the photo namer holds the folder to.
  if (strlen(dir) >= PhotoNamer::kMaxDir) {
    return Status(Code::kInvalidArgument, "output folder %.64s...: longer than %zu characters", dir,
                  PhotoNamer::kMaxDir - 1);
  }
  char probe[PhotoNamer::kMaxDir + 32];
  snprintf(probe, sizeof(probe), "%s/.refocusd-check-XXXXXX", dir);
  const int fd = mkostemp(probe, O_CLOEXEC);
  if (fd < 0) {
    ErrnoText(errno, text, sizeof(text));
    return Status(Code::kIoError, "output folder %s: cannot write in it: %s", dir, text);
  }
  close(fd);
  if (unlink(probe) != 0) {
    ErrnoText(errno, text, sizeof(text));
    return Status(Code::kIoError, "output folder %s: cannot remove the test file %s: %s", dir,
                  probe, text);
  }
  return Status::Ok();
}

}  // namespace lb
