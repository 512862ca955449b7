#include "firmware/storage/atomic_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/storage/errno_text.h"
#include "firmware/storage/output_target.h"
#include "firmware/storage/temp_registry.h"

namespace lb {
AtomicFile::~AtomicFile() { Abort(); }

Status AtomicFile::Fail(int err, const char* what) {
  char text[96];
  ErrnoText(err, text, sizeof(text));
  const Code code = (err == ENOENT || err == ENOTDIR) ? Code::kNotFound : Code::kIoError;
  if (what == nullptr) return Status(code, "%s: %s", final_path_, text);
  return Status(code, "%s: %s: %s", final_path_, what, text);
}

Status AtomicFile::Open(const char* final_path) {
  if (fd_ >= 0) return Status(Code::kBusy, "%s: already open for %s", final_path, final_path_);
  Abort();
  if (final_path == nullptr || final_path[0] == '\0') {
    return Status(Code::kInvalidArgument, "empty output path");
  }
  const size_t len = strlen(final_path);
  const char* slash = strrchr(final_path, '/');
  const char* name = slash ? slash + 1 : final_path;
  // ".<name>.XXXXXX" adds 8 characters to the name.
  if (len + 8 >= kMaxPath) {
    return Status(Code::kInvalidArgument, "%.64s...: path longer than %zu characters", final_path,
                  kMaxPath - 9);
  }
  if (name[0] == '\0') return Status(Code::kInvalidArgument, "%s: names a directory", final_path);
  memcpy(final_path_, final_path, len + 1);
  const size_t dir_len = static_cast<size_t>(name - final_path);
  if (dir_len == 0) {
    snprintf(dir_path_, sizeof(dir_path_), ".");
  } else {
    // Keep the slash for "/x.jpg" so the directory is "/" and not "".
    const size_t keep = dir_len == 1 ? 1 : dir_len - 1;
    memcpy(dir_path_, final_path, keep);
    dir_path_[keep] = '\0';
  }
  snprintf(temp_path_, sizeof(temp_path_), "%.*s.%s.XXXXXX", static_cast<int>(dir_len), final_path,
           name);
  const int fd = mkostemp(temp_path_, O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    temp_path_[0] = '\0';
    char what[kMaxPath + 32];
    snprintf(what, sizeof(what), "cannot create a file in %s", dir_path_);
    return Fail(err, what);
  }
  fd_ = fd;
  error_ = 0;
  registered_ = temp_registry::Add(temp_path_);
  // mkostemp creates 0600; pictures are for everyone to read.
  if (fchmod(fd_, 0644) != 0) {
    const int err = errno;
    Abort();
    return Fail(err, "chmod");
  }
  return Status::Ok();
}

Status AtomicFile::Write(const void* data, size_t size) {
  if (fd_ < 0) return Status(Code::kInternal, "%s: write to a file that is not open", final_path_);
  if (error_ != 0) return Fail(error_, "after an earlier failed write");
  const uint8_t* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = write(fd_, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      error_ = errno;
      return Fail(error_, nullptr);
    }
    if (n == 0) {  // a regular file never does this; treat it as a full medium
      error_ = ENOSPC;
      return Fail(error_, nullptr);
    }
    p += n;
    size -= static_cast<size_t>(n);
  }
  return Status::Ok();
}

int AtomicFile::RenameNoReplace() {
  if (renameat2(AT_FDCWD, temp_path_, AT_FDCWD, final_path_, RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return errno;
  // link() fails on a taken name as well; the temporary then goes as after a rename.
  if (link(temp_path_, final_path_) == 0) {
    unlink(temp_path_);
    return 0;
  }
  if (errno != EPERM && errno != EOPNOTSUPP) return errno;
  struct stat st;
  if (lstat(final_path_, &st) == 0) return EEXIST;
  return rename(temp_path_, final_path_) == 0 ? 0 : errno;
}

Status AtomicFile::Commit(Replace replace) {
  if (fd_ < 0) return Status(Code::kInternal, "%s: commit of a file that is not open", final_path_);
  if (error_ != 0) {
    Status status = Fail(error_, "not committed after a failed write");
    Abort();
    return status;
  }
  // The data must be on the medium before the rename makes it visible, or a power cut could
  // publish an empty file under the final name.
  if (fsync(fd_) != 0) {
    const int err = errno;
    Abort();
    return Fail(err, nullptr);
  }
  const int fd = fd_;
  fd_ = -1;
  if (close(fd) != 0) {
    const int err = errno;
    Forget();
    return Fail(err, nullptr);
  }
  // The target may have become a device, a FIFO or a link since the run began: a rename would
  // replace it.
  const Status kind = CheckTargetKind(final_path_);
  if (!kind.ok()) {
    Forget();
    return kind;
  }
  // A signal between the rename and MarkCommitted would end the process after the file was
  // replaced: they wait until the file is in place and marked (temp_registry.h).
  sigset_t stops, old;
  sigemptyset(&stops);
  for (int sig : temp_registry::kStopSignals) sigaddset(&stops, sig);
  pthread_sigmask(SIG_BLOCK, &stops, &old);
  const int err = replace == Replace::kNever             ? RenameNoReplace()
                  : rename(temp_path_, final_path_) == 0 ? 0
                                                         : errno;
  if (err == 0) temp_registry::MarkCommitted();
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (err != 0) {
    Forget();
    if (err == EEXIST) {
      return Status(Code::kInvalidArgument, "%s exists: a new photo never replaces one",
                    final_path_);
    }
    return Fail(err, "rename");
  }
  Unregister();
  temp_path_[0] = '\0';
  // The rename itself is durable only once the directory is synced.
  const int dir_fd = open(dir_path_, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) return Fail(errno, "sync directory");
  int sync_err = 0;
  // Some filesystems cannot sync a directory (EINVAL); the file is complete either way.
  if (fsync(dir_fd) != 0 && errno != EINVAL) sync_err = errno;
  close(dir_fd);
  if (sync_err != 0) return Fail(sync_err, "sync directory");
  return Status::Ok();
}

void AtomicFile::Abort() {
  if (fd_ >= 0) {
    close(fd_);
    fd_ = -1;
  }
  if (temp_path_[0] != '\0') Forget();
  error_ = 0;
}

void AtomicFile::Forget() {
  // Unlinked before it leaves the registry, so a signal in between finds nothing left.
  unlink(temp_path_);
  Unregister();
  temp_path_[0] = '\0';
}

void AtomicFile::Unregister() {
  if (registered_) temp_registry::Remove(temp_path_);
  registered_ = false;
}

}  // namespace lb
