#include "common/yaml_reader.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace sedbridge::config {

SourceLocation LocationOf(const YAML::Node& node, const std::string& file) {
  SourceLocation loc{file, 0, 0};
  if (node) {
    const YAML::Mark m = node.Mark();
    if (m.line >= 0) {
      loc.line = m.line + 1;
      loc.column = m.column + 1;
    }
  }
  return loc;
}

namespace internal {
void FailNonFinite(const YAML::Node& node, const std::string& file, const std::string& what) {
  const std::string text = node.IsScalar() ? " (got '" + node.Scalar() + "')" : "";
  throw ConfigError(LocationOf(node, file), "'" + what + "' must be a finite number" + text);
}
}  // namespace internal

namespace {

// Most nodes a config may have. Aliases share nodes, so a few lines of anchors can expand
// into billions of visits (or a cycle); the walk stops with an error instead.
constexpr std::size_t kMaxConfigNodes = 1000000;

// Iterative walk (a deeply nested document must not overflow the stack here).
void CheckDuplicates(const YAML::Node& root, const std::string& file) {
  std::vector<YAML::Node> todo{root};
  std::size_t visited = 0;
  while (!todo.empty()) {
    if (++visited > kMaxConfigNodes)
      throw ConfigError({file, 0, 0}, "more than " + std::to_string(kMaxConfigNodes) +
                                          " YAML nodes (alias expansion?): not a config");
    const YAML::Node n = todo.back();
    todo.pop_back();
    if (n.IsMap()) {
      std::set<std::string> seen;
      for (auto it = n.begin(); it != n.end(); ++it) {
        // Only scalar keys can be compared by text; complex keys are rejected by every reader.
        if (it->first.IsScalar() && !seen.insert(it->first.Scalar()).second)
          throw ConfigError(LocationOf(it->first, file),
                            "duplicate key '" + it->first.Scalar() + "' (given earlier in the same mapping)");
        todo.push_back(it->second);
      }
    } else if (n.IsSequence()) {
      for (auto it = n.begin(); it != n.end(); ++it) todo.push_back(*it);
    }
  }
}

}  // namespace

void CheckNoDuplicateKeys(const YAML::Node& root, const std::string& file) { CheckDuplicates(root, file); }

YamlDocument LoadYamlString(const std::string& text, const std::string& file) {
  YamlDocument doc;
  try {
    doc = {file, YAML::Load(text)};
  } catch (const YAML::ParserException& e) {
    throw ConfigError({file, e.mark.line + 1, e.mark.column + 1}, e.msg);
  }
  CheckNoDuplicateKeys(doc.root, file);
  return doc;
}

YamlDocument LoadYamlFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError({path, 0, 0}, "cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  return LoadYamlString(ss.str(), path);
}

MapReader::MapReader(const YAML::Node& node, std::string file)
    : node_(node), file_(std::move(file)) {
  if (!node_ || !node_.IsMap()) {
    throw ConfigError(LocationOf(node_, file_), "expected a mapping (key: value pairs)");
  }
}

bool MapReader::Has(const std::string& key) const { return bool(node_[key]); }

YAML::Node MapReader::Get(const std::string& key, bool required) {
  used_.insert(key);
  YAML::Node v = node_[key];
  if (!v && required) Fail("missing required key '" + key + "'");
  return v;
}

YAML::Node MapReader::Node(const std::string& key) { return Get(key, true); }

MapReader MapReader::Child(const std::string& key) { return MapReader(Get(key, true), file_); }

std::string MapReader::RequiredChoice(const std::string& key,
                                      const std::vector<std::string>& choices) {
  YAML::Node v = Get(key, true);
  std::string s = Convert<std::string>(v, key);
  if (std::find(choices.begin(), choices.end(), s) == choices.end()) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    Fail(v, "'" + key + "' must be one of: " + list + " (got '" + s + "')");
  }
  return s;
}

std::string MapReader::OptionalChoice(const std::string& key,
                                      const std::vector<std::string>& choices,
                                      const std::string& fallback) {
  if (!Has(key)) {
    used_.insert(key);
    return fallback;
  }
  return RequiredChoice(key, choices);
}

void MapReader::Finish() const {
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.Scalar();
    if (!used_.count(key)) {
      throw ConfigError(LocationOf(it->first, file_), "unknown key '" + key + "'");
    }
  }
}

void MapReader::Fail(const YAML::Node& node, const std::string& message) const {
  throw ConfigError(LocationOf(node, file_), message);
}

void MapReader::Fail(const std::string& message) const { Fail(node_, message); }

}  // namespace sedbridge::config
