#pragma once
// Where a line stands in a file: tests that check an error's file:line:column against the
// file they wrote or a shipped one.

#include <fstream>
#include <string>

namespace sedbridge::test_util {

/// 1-based number of the first line of the file at `path` that starts with `start` (0: none).
inline int LineOf(const std::string& path, const std::string& start) {
  std::ifstream in(path);
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.rfind(start, 0) == 0) return number;
  }
  return 0;
}

}  // namespace sedbridge::test_util
