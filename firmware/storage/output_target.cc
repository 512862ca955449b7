#include "firmware/storage/output_target.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "firmware/storage/errno_text.h"

namespace lb {

Status CheckTargetKind(const char* path) {
  struct stat st;
  if (lstat(path, &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return Status::Ok();  // the folder check says why
    char text[96];
    ErrnoText(errno, text, sizeof(text));
    return Status(Code::kIoError, "%s: %s", path, text);
  }
  if (S_ISLNK(st.st_mode)) {
    return Status(Code::kInvalidArgument,
                  "%s is a symbolic link: name the file itself, or a new one", path);
  }
  if (!S_ISREG(st.st_mode)) {
    return Status(Code::kInvalidArgument,
                  "%s is not a regular file (a device, a FIFO or a folder): name a new file", path);
  }
  return Status::Ok();
}

Status CheckOutputTarget(const char* path, const char* const* inputs, int32_t input_count) {
  if (path == nullptr || path[0] == '\0') {
    return Status(Code::kInvalidArgument, "empty output path");
  }
  LB_RETURN_IF_ERROR(CheckTargetKind(path));
  struct stat target;
  const bool exists = stat(path, &target) == 0;
  for (int32_t i = 0; exists && i < input_count; ++i) {
    struct stat in;
    if (stat(inputs[i], &in) != 0 || in.st_dev != target.st_dev || in.st_ino != target.st_ino) {
      continue;
    }
    if (strcmp(inputs[i], path) == 0) {
      return Status(Code::kInvalidArgument,
                    "%s is an input of this run: write the output somewhere else", path);
    }
    return Status(Code::kInvalidArgument,
                  "%s is an input of this run (as %s): write the output somewhere else", path,
                  inputs[i]);
  }
  const char* slash = strrchr(path, '/');
  const std::string dir =
      slash == nullptr ? std::string(".") : std::string(path, slash == path ? 1 : slash - path);
  struct stat d;
  if (stat(dir.c_str(), &d) != 0) {
    const int err = errno;
    char text[96];
    ErrnoText(err, text, sizeof(text));
    return Status(err == ENOENT || err == ENOTDIR ? Code::kNotFound : Code::kIoError,
                  "%s: the folder %s: %s", path, dir.c_str(), text);
  }
  if (!S_ISDIR(d.st_mode)) {
    return Status(Code::kNotFound, "%s: %s is not a folder", path, dir.c_str());
  }
  if (access(dir.c_str(), W_OK | X_OK) != 0) {
    char text[96];
    ErrnoText(errno, text, sizeof(text));
    return Status(Code::kIoError, "%s: cannot write in %s: %s", path, dir.c_str(), text);
  }
  return Status::Ok();
}

}  // namespace lb
