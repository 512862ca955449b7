// With nftw, not a shell running rm: under qemu-user (the aarch64 and armhf CI runs), the child
// of a fork right after a test's threads end can hang on a lock, and the whole CI stage with it.
// No shell, no fork.
#include "tests/support/remove_tree.h"

#include <ftw.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdio>

namespace lb::test {
namespace {

// FTW_DEPTH hands over a folder after its contents, so `remove` finds it empty; FTW_PHYS hands
// over a link as the link. A failure does not stop the walk (it removes what it can, as rm does);
// RemoveTree then looks whether `dir` is gone.
int RemoveEntry(const char* path, const struct stat* /*st*/, int /*type*/, struct FTW* /*ftw*/) {
  (void)remove(path);
  return 0;
}

}  // namespace

bool RemoveTree(const std::string& dir) {
  (void)nftw(dir.c_str(), RemoveEntry, 16, FTW_DEPTH | FTW_PHYS);
  struct stat st;
  return lstat(dir.c_str(), &st) != 0 && errno == ENOENT;
}

}  // namespace lb::test
