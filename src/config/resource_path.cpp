#include "config/resource_path.h"

#include <cstdlib>
#include <filesystem>

namespace sedbridge::config {

std::string SourceRoot() {
  if (const char* env = std::getenv("SEDBRIDGE_ROOT")) return env;
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

}  // namespace sedbridge::config
