#include "common/resource_path.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

// Set by the top-level CMakeLists from the install layout; stand-alone builds of parts of
// the tree (the fuzz and sanitizer projects) get the GNU default.
#ifndef SEDBRIDGE_DATA_FROM_BIN
#define SEDBRIDGE_DATA_FROM_BIN "../share/sedbridge"
#endif

namespace sedbridge::config {

std::string InstalledDataRoot() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "";
  const fs::path data = (exe.parent_path() / SEDBRIDGE_DATA_FROM_BIN).lexically_normal();
  // config/ must be there: a build-tree binary has no share/ beside it.
  return fs::is_directory(data / "config", ec) ? data.string() : "";
}

std::string SourceRoot() {
  if (const char* env = std::getenv("SEDBRIDGE_ROOT"); env && *env) return env;
  // Computed once: the binary does not move while it runs.
  static const std::string installed = InstalledDataRoot();
  if (!installed.empty()) return installed;
  return SEDBRIDGE_SOURCE_DIR;
}

std::string ResolveResource(const std::string& relative) {
  namespace fs = std::filesystem;
  if (fs::exists(relative)) return relative;
  if (fs::path(relative).is_absolute()) return relative;
  const fs::path candidate = fs::path(SourceRoot()) / relative;
  if (fs::exists(candidate)) return candidate.string();
  return relative;
}

std::string ResolveNameOrPath(const std::string& name_or_path, const std::string& shipped_folder) {
  namespace fs = std::filesystem;
  const fs::path p(name_or_path);
  const bool bare_name = !name_or_path.empty() && !p.has_parent_path() && !p.has_extension();
  if (bare_name && !fs::exists(p)) return ResolveResource(shipped_folder + "/" + name_or_path + ".yaml");
  return ResolveResource(name_or_path);
}

}  // namespace sedbridge::config
