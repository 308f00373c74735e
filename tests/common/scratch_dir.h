#pragma once
// A scratch folder for the files a test writes (bad YAML, fixtures in other units, output
// contracts): one per test process (ctest -j runs a file's tests in parallel processes),
// removed when the process exits, so test runs leave nothing in the system's temp folder.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace sedbridge::testing {

inline const std::string& ScratchDir() {
  struct Dir {
    std::string path = (std::filesystem::temp_directory_path() / ("sedbridge_test_" + std::to_string(::getpid()))).string();
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

}  // namespace sedbridge::testing
