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

/// The one rule for "a shipped config by name, or a path" (models, sensor and display
/// profiles), first match of:
///   1. a file or folder that exists as given (relative to the working directory, or
///      absolute): returned unchanged;
///   2. a bare name (no '/', no extension: "B", "uskin_4x4", "suction_4x4"): the shipped
///      `<shipped_folder>/<name>.yaml`, resolved with ResolveResource;
///   3. anything else ("my/profile.yaml", "B.msh"): ResolveResource(name_or_path).
/// Returns a path that may not exist (the caller's open then names it).
/// @param[in] shipped_folder  relative to SourceRoot(), e.g. "config/displays"
std::string ResolveNameOrPath(const std::string& name_or_path, const std::string& shipped_folder);

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
