#pragma once
// Helpers shared by the model tests: fixture text and line edits for error cases.

#include <fstream>
#include <sstream>
#include <string>

namespace sedbridge::model::testing {

inline std::string FixturePath(const std::string& name) {
  return std::string(SEDBRIDGE_MODEL_FIXTURE_DIR) + "/" + name;
}

inline std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Replaces 1-based line `line` of `text` (which must exist) by `replacement`.
inline std::string ReplaceLine(const std::string& text, int line, const std::string& replacement) {
  std::istringstream in(text);
  std::string out, l;
  int n = 0;
  while (std::getline(in, l)) out += (++n == line ? replacement : l) + "\n";
  if (line > n) throw std::out_of_range("no line " + std::to_string(line));
  return out;
}

/// The 3-tet fixture: epidermis tet 10 (line 35), dermis tet 11 (line 37), bone tet 12
/// (line 39); nodes 1..6, coordinates on lines 25..30.
inline std::string ThreeTets() { return ReadText(FixturePath("three_tets.msh")); }

}  // namespace sedbridge::model::testing
