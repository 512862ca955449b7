// The only door from a web request to the photo folder: which names may be asked for, opening
// one without following a symbolic link, listing the folder, and choosing the name of a saved
// re-render. The HTTP library has already percent-decoded the path, so the checks here see what
// the file system would see ("%2e%2e%2f" arrives as "../" and is refused like it).
#pragma once

#include <sys/stat.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/status.h"

namespace lb {

// One path component of [A-Za-z0-9_.-], no leading dot, ending in .jpg or .jpeg (any case), at
// most kMaxPhotoName characters.
inline constexpr size_t kMaxPhotoName = 128;
bool IsServablePhotoName(const char* name);

// Opens the folder (O_DIRECTORY, close-on-exec); kNotFound while it is missing (a card not
// mounted).
Status OpenPhotoFolder(const char* dir, int* dir_fd);

// Opens `name` in the folder read-only with O_NOFOLLOW and checks it is a regular file: a name
// the rule refuses is kInvalidArgument, an absent file kNotFound, a symbolic link, folder or
// device kInvalidArgument (it is never followed). On success *fd is open (the caller closes it)
// and *st describes it.
Status OpenPhoto(int dir_fd, const char* name, int* fd, struct stat* st);

struct PhotoEntry {
  std::string name;
  int64_t mtime_ns = 0;
  int64_t size = 0;
};

// Regular files with servable names, newest first (modification time, then name, descending),
// at most `max_entries` of them (the newest).
Status ListPhotoFolder(int dir_fd, size_t max_entries, std::vector<PhotoEntry>* photos);

// The name a re-render of `name` is saved under: its stem without a trailing _rN, then _r1, _r2,
// ... (the first that no entry of the folder has), with the original's extension. kBusy when
// _r1 to _r99 are all taken (the page answers 409: only removing some helps), kInvalidArgument
// when the result would be too long.
Status ChooseRerenderName(int dir_fd, const char* name, char* out, size_t size);

}  // namespace lb
