#pragma once
// A small, strict command-line parser: --name VALUE, --name=VALUE, --flag, positionals.
// Unknown options are errors. `--help` prints the generated help and returns false.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace sedbridge::app {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ArgParser {
 public:
  /// `program` e.g. "sedbridge press"; `description` is printed under the usage line.
  ArgParser(std::string program, std::string description);

  /// Option taking a value. `fallback` empty = no default shown.
  ArgParser& Option(const std::string& name, const std::string& value_name,
                    const std::string& help, const std::string& fallback = "");
  ArgParser& Flag(const std::string& name, const std::string& help);
  ArgParser& Positional(const std::string& name, const std::string& help, bool required = true);
  /// Extra text printed at the end of --help (examples, output files).
  ArgParser& Epilog(const std::string& text);

  /// Parses argv[1..argc). Returns false when --help was printed. Throws UsageError.
  bool Parse(int argc, char** argv);

  std::string Help() const;

  bool Has(const std::string& name) const;
  std::string Get(const std::string& name) const;  ///< value or fallback; throws if neither
  std::optional<std::string> GetOptional(const std::string& name) const;
  double GetDouble(const std::string& name) const;
  long GetInt(const std::string& name) const;
  bool GetFlag(const std::string& name) const;

 private:
  struct Spec {
    std::string name, value_name, help, fallback;
    bool is_flag = false;
  };
  struct PositionalSpec {
    std::string name, help;
    bool required = true;
  };
  const Spec* FindSpec(const std::string& name) const;

  std::string program_, description_, epilog_;
  std::vector<Spec> options_;
  std::vector<PositionalSpec> positionals_;
  std::map<std::string, std::string> values_;
};

}  // namespace sedbridge::app
