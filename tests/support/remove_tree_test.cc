// RemoveTree removes a folder with everything under it, removes the links in it without
// following them (what they point at, outside the folder, survives), and calls a missing
// folder gone.
#include "tests/support/remove_tree.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace lb::test {
namespace {

bool Exists(const std::string& path) {
  struct stat st;
  return lstat(path.c_str(), &st) == 0;
}

void Write(const std::string& path) {
  FILE* f = fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  fputs("bytes", f);
  fclose(f);
}

TEST(RemoveTree, RemovesNestedFoldersAndLinksButNotWhatTheyPointAt) {
  char outside_tmpl[] = "/tmp/lb_remove_tree_outside_XXXXXX";
  ASSERT_NE(mkdtemp(outside_tmpl), nullptr);
  const std::string outside = outside_tmpl;
  const std::string target = outside + "/target.txt";
  Write(target);
  const std::string target_dir = outside + "/kept";
  ASSERT_EQ(mkdir(target_dir.c_str(), 0755), 0);
  Write(target_dir + "/inside.txt");

  char tmpl[] = "/tmp/lb_remove_tree_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  Write(dir + "/top.txt");
  ASSERT_EQ(mkdir((dir + "/sub").c_str(), 0755), 0);
  Write(dir + "/sub/a.txt");
  ASSERT_EQ(mkdir((dir + "/sub/deeper").c_str(), 0755), 0);
  Write(dir + "/sub/deeper/b.txt");
  ASSERT_EQ(symlink(target.c_str(), (dir + "/sub/link_to_file").c_str()), 0);
  ASSERT_EQ(symlink(target_dir.c_str(), (dir + "/link_to_folder").c_str()), 0);

  EXPECT_TRUE(RemoveTree(dir));
  EXPECT_FALSE(Exists(dir));
  EXPECT_TRUE(Exists(target)) << "the link's target outside the folder was removed";
  EXPECT_TRUE(Exists(target_dir + "/inside.txt")) << "a link to a folder was followed";

  EXPECT_TRUE(RemoveTree(outside));
  EXPECT_FALSE(Exists(outside));
}

TEST(RemoveTree, MissingFolderIsGone) {
  char tmpl[] = "/tmp/lb_remove_tree_missing_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string missing = std::string(tmpl) + "/never_made";
  EXPECT_TRUE(RemoveTree(missing));
  EXPECT_TRUE(RemoveTree(tmpl));
  EXPECT_FALSE(Exists(tmpl));
  EXPECT_TRUE(RemoveTree(tmpl)) << "a second call, on a folder already gone";
}

}  // namespace
}  // namespace lb::test
