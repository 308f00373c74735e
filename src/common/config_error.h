#pragma once
// Errors in user input (YAML, meshes, logs) that say where: "file:line:column: message".

#include <stdexcept>
#include <string>

namespace sedbridge::config {

/// Location in a text file; line and column are 1-based, 0 means "unknown".
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;

  /// "file:line:column", "file:line" or "file" depending on what is known.
  std::string str() const;
};

/// Thrown for any bad user input. what() is "file:line:column: message".
class ConfigError : public std::runtime_error {
 public:
  ConfigError(SourceLocation where, const std::string& message);
  const SourceLocation& where() const { return where_; }
  const std::string& message() const { return message_; }

 private:
  SourceLocation where_;
  std::string message_;
};

}  // namespace sedbridge::config
