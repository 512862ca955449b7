#include "firmware/daemon/photo_namer.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace lb {
namespace {

constexpr size_t kPhotoNameLength = 28;  // IMG_ + 8 + _ + 6 + _ + 4 + .jpg
constexpr size_t kTempSuffix = 7;        // "." + mkstemp's six characters

bool Digits(const char* p, int n) {
  for (int i = 0; i < n; ++i) {
    if (p[i] < '0' || p[i] > '9') return false;
  }
  return true;
}

}  // namespace

bool PhotoNamer::IsPhotoName(const char* name, int32_t* counter) {
  if (strlen(name) != kPhotoNameLength || strncmp(name, "IMG_", 4) != 0 || !Digits(name + 4, 8) ||
      name[12] != '_' || !Digits(name + 13, 6) || name[19] != '_' || !Digits(name + 20, 4) ||
      strcmp(name + 24, ".jpg") != 0) {
    return false;
  }
  *counter =
      (name[20] - '0') * 1000 + (name[21] - '0') * 100 + (name[22] - '0') * 10 + (name[23] - '0');
  return true;
}

bool PhotoNamer::IsTemporaryName(const char* name) {
  if (name[0] != '.' || strlen(name) != 1 + kPhotoNameLength + kTempSuffix) return false;
  char photo[kPhotoNameLength + 1];
  memcpy(photo, name + 1, kPhotoNameLength);
  photo[kPhotoNameLength] = '\0';
  int32_t counter = 0;
  return IsPhotoName(photo, &counter) && name[1 + kPhotoNameLength] == '.';
}

Status PhotoNamer::Scan(const char* dir, int* removed) {
  *removed = 0;
  if (strlen(dir) >= kMaxDir) {
    return Status(Code::kInvalidArgument, "%.64s...: folder name longer than %zu characters", dir,
                  kMaxDir - 1);
  }
  snprintf(dir_, sizeof(dir_), "%s", dir);
  next_ = chosen_ = 1;
  DIR* d = opendir(dir_);
  if (d == nullptr) {
    if (errno == ENOENT) return Status::Ok();
    return Status(Code::kIoError, "%s: cannot list: %s", dir_, strerror(errno));
  }
  int32_t highest = 0;
  Status status;
  for (dirent* e; (e = readdir(d)) != nullptr;) {
    int32_t counter = 0;
    if (IsPhotoName(e->d_name, &counter)) {
      if (counter > highest) highest = counter;
    } else if (IsTemporaryName(e->d_name)) {
      if (unlinkat(dirfd(d), e->d_name, 0) == 0) {
        ++*removed;
      } else if (status.ok()) {
        status = Status(Code::kIoError, "%s/%s: cannot remove a stale temporary: %s", dir_,
                        e->d_name, strerror(errno));
      }
    }
  }
  closedir(d);
  next_ = chosen_ = highest % kMaxCounter + 1;
  return status;
}

Status PhotoNamer::Next(const tm& t, char* path, size_t size) {
  int32_t c = next_;
  for (int32_t tries = 0; tries < kMaxCounter; ++tries) {
    const int n =
        snprintf(path, size, "%s/IMG_%04d%02d%02d_%02d%02d%02d_%04d.jpg", dir_, t.tm_year + 1900,
                 t.tm_mon + 1, t.tm_mday, t.tm_hour, t.tm_min, t.tm_sec, static_cast<int>(c));
    if (n < 0 || static_cast<size_t>(n) >= size) {
      return Status(Code::kInvalidArgument, "%s: photo path longer than %zu characters", dir_,
                    size - 1);
    }
    // Any failure to look (no such folder, no permission) is reported by the write itself.
    struct stat st;
    if (lstat(path, &st) != 0) {
      chosen_ = c;
      return Status::Ok();
    }
    c = c % kMaxCounter + 1;
  }
  return Status(Code::kBusy, "%s: all %d numbers for this second are taken", dir_, kMaxCounter);
}

}  // namespace lb
