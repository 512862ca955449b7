#include "firmware/web/photo_folder.h"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <strings.h>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "firmware/storage/errno_text.h"

namespace lb {
namespace {

// ErrnoText as an expression: ErrText(err).text lives to the end of the full expression.
struct ErrText {
  explicit ErrText(int err) { ErrnoText(err, text, sizeof(text)); }
  char text[96];
};

bool EndsWithNoCase(const char* s, size_t n, const char* suffix) {
  const size_t m = strlen(suffix);
  return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

// The extension of a servable name: ".jpg" or ".jpeg" as written.
size_t ExtensionLength(const char* name, size_t n) {
  return EndsWithNoCase(name, n, ".jpeg") ? 5 : 4;
}

}  // namespace

bool IsServablePhotoName(const char* name) {
  const size_t n = strnlen(name, kMaxPhotoName + 1);
  if (n == 0 || n > kMaxPhotoName || name[0] == '.') return false;
  for (size_t i = 0; i < n; ++i) {
    const char c = name[i];
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) return false;
  }
  // Something before the extension: ".jpg" alone has a leading dot already.
  return EndsWithNoCase(name, n, ".jpg") || EndsWithNoCase(name, n, ".jpeg");
}

Status OpenPhotoFolder(const char* dir, int* dir_fd) {
  *dir_fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (*dir_fd >= 0) return Status::Ok();
  const int err = errno;
  return Status(err == ENOENT ? Code::kNotFound : Code::kIoError, "photo folder %s: %s", dir,
                ErrText(err).text);
}

Status OpenPhoto(int dir_fd, const char* name, int* fd, struct stat* st) {
  *fd = -1;
  if (!IsServablePhotoName(name)) {
    return Status(Code::kInvalidArgument,
                  "not a photo name (one name of letters, digits, _ . -, "
                  "ending in .jpg or .jpeg)");
  }
  const int f = openat(dir_fd, name, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (f < 0) {
    const int err = errno;
    if (err == ENOENT) return Status(Code::kNotFound, "%s: no such photo", name);
    // O_NOFOLLOW on a symbolic link: ELOOP.
    if (err == ELOOP) return Status(Code::kInvalidArgument, "%s: a symbolic link", name);
    return Status(Code::kIoError, "%s: %s", name, ErrText(err).text);
  }
  if (fstat(f, st) != 0 || !S_ISREG(st->st_mode)) {
    close(f);
    return Status(Code::kInvalidArgument, "%s: not a regular file", name);
  }
  *fd = f;
  return Status::Ok();
}

Status ListPhotoFolder(int dir_fd, size_t max_entries, std::vector<PhotoEntry>* photos) {
  photos->clear();
  const int own = fcntl(dir_fd, F_DUPFD_CLOEXEC, 0);
  if (own < 0) return Status(Code::kIoError, "photo folder: %s", ErrText(errno).text);
  DIR* d = fdopendir(own);
  if (d == nullptr) {
    const int err = errno;
    close(own);
    return Status(Code::kIoError, "photo folder: %s", ErrText(err).text);
  }
  rewinddir(d);  // the duplicate shares the position of earlier listings
  while (const dirent* e = readdir(d)) {
    if (!IsServablePhotoName(e->d_name)) continue;
    struct stat st;
    if (fstatat(dir_fd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode)) {
      continue;
    }
    PhotoEntry p;
    p.name = e->d_name;
    p.mtime_ns = static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
    p.size = st.st_size;
    photos->push_back(std::move(p));
  }
  closedir(d);
  std::sort(photos->begin(), photos->end(), [](const PhotoEntry& a, const PhotoEntry& b) {
    if (a.mtime_ns != b.mtime_ns) return a.mtime_ns > b.mtime_ns;
    return a.name > b.name;
  });
  if (photos->size() > max_entries) photos->resize(max_entries);
  return Status::Ok();
}

Status ChooseRerenderName(int dir_fd, const char* name, char* out, size_t size) {
  if (!IsServablePhotoName(name)) return Status(Code::kInvalidArgument, "not a photo name");
  const size_t n = strlen(name);
  const size_t ext = ExtensionLength(name, n);
  size_t stem = n - ext;
  // IMG_..._0001_r2.jpg saves as IMG_..._0001_r3.jpg, not _r2_r1.
  size_t digits = 0;
  while (digits < stem && digits < 2 && name[stem - 1 - digits] >= '0' &&
         name[stem - 1 - digits] <= '9') {
    ++digits;
  }
  if (digits > 0 && stem >= digits + 2 && name[stem - digits - 1] == 'r' &&
      name[stem - digits - 2] == '_') {
    stem -= digits + 2;
  }
  for (int k = 1; k <= 99; ++k) {
    const int len =
        snprintf(out, size, "%.*s_r%d%s", static_cast<int>(stem), name, k, name + n - ext);
    if (len < 0 || static_cast<size_t>(len) >= size || !IsServablePhotoName(out)) {
      return Status(Code::kInvalidArgument, "%s: the name of its re-render would be too long",
                    name);
    }
    struct stat st;
    if (fstatat(dir_fd, out, &st, AT_SYMLINK_NOFOLLOW) != 0 && errno == ENOENT) {
      return Status::Ok();
    }
  }
  return Status(Code::kBusy, "%s: re-renders _r1 to _r99 all exist", name);
}

}  // namespace lb
