// Removes a test's scratch folder and everything under it, without a shell.
#pragma once

#include <string>

namespace lb::test {

// Removes `dir` and everything under it; symbolic links are removed, never followed. True when
// `dir` is gone afterwards (also when it did not exist), false when something is left.
bool RemoveTree(const std::string& dir);

}  // namespace lb::test
