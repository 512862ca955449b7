// AtomicFile: writes a file under a hidden temporary name in the destination directory and
// renames it over the final name only once every byte is on the medium. A failure at any step
// (missing directory, full card, I/O error, the caller giving up) leaves neither the final name
// nor the temporary behind, and nor does a signal where the program installed
// RemoveTemporariesOnSignals (temp_registry.h). The rename never replaces anything but a
// regular file (output_target.h).
#pragma once

#include <cstddef>

#include "algo/core/status.h"

namespace lb {

class AtomicFile {
 public:
  static constexpr size_t kMaxPath = 1024;
  // What the commit may put its file over: a regular file of the final name (a re-run's output),
  // or nothing at all (a new photo beside others: kInvalidArgument when the name is taken).
  enum class Replace : uint8_t { kRegularFile, kNever };

  AtomicFile() = default;
  ~AtomicFile();  // aborts when not committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Creates `.<name>.XXXXXX` (mode 0644, close-on-exec) next to `final_path`.
  Status Open(const char* final_path);

  // Writes all of `size` bytes (retrying short writes and EINTR). After a failure every later
  // Write and Commit fail too, so a caller that missed one error cannot commit a partial file.
  Status Write(const void* data, size_t size);

  // fsync, close, rename to the final name, fsync the directory. With Replace::kNever the rename
  // itself refuses a taken name (renameat2 RENAME_NOREPLACE; on a filesystem without it, a hard
  // link; on one without links either, such as FAT, a check just before the rename).
  Status Commit(Replace replace = Replace::kRegularFile);

  // Closes and unlinks the temporary; harmless when nothing is open.
  void Abort();

  int fd() const { return fd_; }
  bool is_open() const { return fd_ >= 0; }
  const char* path() const { return final_path_; }

 private:
  Status Fail(int err, const char* what);
  int RenameNoReplace();  // 0, or an errno (EEXIST: the name is taken)
  void Forget();          // unlinks the temporary and forgets it
  void Unregister();      // drops it from the signal handler's list (temp_registry.h)

  int fd_ = -1;
  int error_ = 0;  // errno of the first failed write, sticky until Abort
  bool registered_ = false;
  char final_path_[kMaxPath] = {};
  char temp_path_[kMaxPath] = {};
  char dir_path_[kMaxPath] = {};
};

}  // namespace lb
