#pragma once
// Strict YAML reading: every value is typed, every error names file:line:column, and a
// key nobody asked for is an error (a typo must not silently fall back to a default).
// A key given twice in one mapping is an error at load time (yaml-cpp keeps the first, so
// `max: 20` then `max: 5` would silently mean 20), and every floating-point value read
// through As/Required/Optional must be finite (.nan, .inf are errors: no config value has a
// use for them, and one reaching a limit defeats it).
//
//   auto doc = LoadYamlFile("config/scenes/paper_press.yaml");
//   MapReader scene(doc.root, doc.file);
//   double dt_s = scene.Optional<double>("dt_s", 1e-3);
//   MapReader solver = scene.Child("solver");
//   ...
//   solver.Finish();
//   scene.Finish();   // throws on the first unknown key, naming its location

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "common/config_error.h"

namespace sedbridge::config {

struct YamlDocument {
  std::string file;
  YAML::Node root;
};

/// Parses a YAML file. Throws ConfigError (with the parser's line/column) on failure, and
/// at the second occurrence of a key repeated within one mapping.
YamlDocument LoadYamlFile(const std::string& path);
/// Parses YAML text; `file` is only used in messages.
YamlDocument LoadYamlString(const std::string& text, const std::string& file);

/// Throws ConfigError at the first mapping key (at any depth under `root`) that repeats an
/// earlier key of the same mapping. LoadYamlFile/LoadYamlString call it.
void CheckNoDuplicateKeys(const YAML::Node& root, const std::string& file);

/// Location of a node in its file.
SourceLocation LocationOf(const YAML::Node& node, const std::string& file);

/// Reads one YAML mapping strictly.
class MapReader {
 public:
  /// Throws if `node` is not a mapping. `file` is used for messages.
  MapReader(const YAML::Node& node, std::string file);

  bool Has(const std::string& key) const;

  /// Required scalar or sequence of scalars; throws naming the mapping if missing.
  template <typename T>
  T Required(const std::string& key);

  /// Optional value; `fallback` when the key is absent.
  template <typename T>
  T Optional(const std::string& key, const T& fallback);

  /// Required string restricted to `choices`.
  std::string RequiredChoice(const std::string& key, const std::vector<std::string>& choices);
  std::string OptionalChoice(const std::string& key, const std::vector<std::string>& choices,
                             const std::string& fallback);

  /// Raw node (marked as used). Throws if missing.
  YAML::Node Node(const std::string& key);
  /// Nested mapping.
  MapReader Child(const std::string& key);

  /// Throws ConfigError at the first key that was never read.
  void Finish() const;

  /// Throws ConfigError located at `node`.
  [[noreturn]] void Fail(const YAML::Node& node, const std::string& message) const;
  [[noreturn]] void Fail(const std::string& message) const;  // at the mapping itself

  const std::string& file() const { return file_; }
  const YAML::Node& node() const { return node_; }

 private:
  YAML::Node Get(const std::string& key, bool required);
  template <typename T>
  T Convert(const YAML::Node& value, const std::string& key) const;

  YAML::Node node_;
  std::string file_;
  std::set<std::string> used_;
};

/// Converts a node, throwing ConfigError at the node on a type mismatch, and on a NaN or
/// infinite float/double (also inside a std::vector of them).
template <typename T>
T As(const YAML::Node& node, const std::string& file, const std::string& what);

// ---- template implementations ----

namespace internal {
template <typename T>
struct IsFloatVector : std::false_type {};
template <typename U, typename A>
struct IsFloatVector<std::vector<U, A>> : std::is_floating_point<U> {};
[[noreturn]] void FailNonFinite(const YAML::Node& node, const std::string& file, const std::string& what);
}  // namespace internal

template <typename T>
T As(const YAML::Node& node, const std::string& file, const std::string& what) {
  T value;
  try {
    value = node.as<T>();
  } catch (const YAML::Exception&) {
    std::string text = node.IsScalar() ? " (got '" + node.Scalar() + "')" : "";
    throw ConfigError(LocationOf(node, file), "'" + what + "' has the wrong type" + text);
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) internal::FailNonFinite(node, file, what);
  } else if constexpr (internal::IsFloatVector<T>::value) {
    for (std::size_t i = 0; i < value.size(); ++i)
      if (!std::isfinite(value[i])) internal::FailNonFinite(node[i], file, what);
  }
  return value;
}

template <typename T>
T MapReader::Convert(const YAML::Node& value, const std::string& key) const {
  return As<T>(value, file_, key);
}

template <typename T>
T MapReader::Required(const std::string& key) {
  return Convert<T>(Get(key, true), key);
}

template <typename T>
T MapReader::Optional(const std::string& key, const T& fallback) {
  YAML::Node v = Get(key, false);
  if (!v) return fallback;
  return Convert<T>(v, key);
}

}  // namespace sedbridge::config
