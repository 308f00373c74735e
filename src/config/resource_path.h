#pragma once
// Finds shipped resources (config/models/B.yaml, config/sensors/...) from any working dir.

#include <string>

namespace sedbridge::config {

/// Resolves `relative` (e.g. "config/models/B.yaml"): returned unchanged if it exists as
/// given; else tried under $SEDBRIDGE_ROOT, then under the source tree the binary was
/// built from. Returns `relative` unchanged when nothing matches (the caller's open fails
/// with the user's own spelling of the path).
std::string ResolveResource(const std::string& relative);

/// The project root the binary was built from (for defaults and tools/ scripts).
std::string SourceRoot();

}  // namespace sedbridge::config
