#pragma once
// Finds shipped resources (config/models/B.yaml, config/sensors/..., tools/plot_*.py) from
// any working dir, for a binary in the build tree and for an installed one.

#include <string>

namespace sedbridge::config {

/// Resolves `relative` (e.g. "config/models/B.yaml"): returned unchanged if it exists as
/// given (relative to the working directory, or absolute); else tried under SourceRoot().
/// Returns `relative` unchanged when nothing matches (the caller's open fails with the
/// user's own spelling of the path).
std::string ResolveResource(const std::string& relative);

/// The folder that holds config/ and tools/, first match of:
///   1. $SEDBRIDGE_ROOT (set and not empty): a checkout or an installed PREFIX/share/sedbridge;
///   2. PREFIX/share/sedbridge when this binary runs from PREFIX/bin (an installed tree,
///      found from /proc/self/exe, so a moved prefix still works);
///   3. the source tree the binary was built from.
std::string SourceRoot();

/// Where the running binary's installed data would be (PREFIX/share/sedbridge), "" when
/// that folder does not exist (e.g. a binary in the build tree).
std::string InstalledDataRoot();

}  // namespace sedbridge::config
