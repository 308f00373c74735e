#pragma once
// Keys documented in a config README: the first column of every table whose header row is
// "| key | ...", backquotes removed ("`dynamics.dt_s`" -> "dynamics.dt_s"). Tests compare
// them with the schema (common/schema_keys.h), both ways.

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace sedbridge::test_util {

inline std::set<std::string> ReadmeKeys(const std::string& path) {
  std::ifstream in(path);
  std::set<std::string> keys;
  bool in_key_table = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("|", 0) != 0) {
      in_key_table = false;
      continue;
    }
    if (line.rfind("| key |", 0) == 0) {
      in_key_table = true;
      continue;
    }
    if (!in_key_table || line.rfind("|---", 0) == 0) continue;
    const std::size_t open = line.find('`'), close = line.find('`', open + 1);
    const std::size_t cell_end = line.find('|', 1);
    if (open == std::string::npos || close == std::string::npos || close > cell_end) continue;
    keys.insert(line.substr(open + 1, close - open - 1));
  }
  return keys;
}

/// The README's key table and a schema (config::SchemaKeys<T>()) name the same keys, both
/// ways; the table must have more than 10 rows (a parse that found nothing fails).
inline void ExpectReadmeNamesSchemaKeys(const std::string& readme_path, const std::vector<std::string>& schema_keys) {
  const std::set<std::string> documented = ReadmeKeys(readme_path);
  ASSERT_GT(documented.size(), 10u) << readme_path;
  const std::set<std::string> schema(schema_keys.begin(), schema_keys.end());
  for (const std::string& key : schema) EXPECT_TRUE(documented.count(key)) << key << " is not in " << readme_path;
  for (const std::string& key : documented) EXPECT_TRUE(schema.count(key)) << key << " (" << readme_path << ") is no schema key";
}

}  // namespace sedbridge::test_util
