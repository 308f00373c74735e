#include "app/arg_parser.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace sedbridge::app {

ArgParser::ArgParser(std::string program, std::string description)
    : program_(std::move(program)), description_(std::move(description)) {}

ArgParser& ArgParser::Option(const std::string& name, const std::string& value_name,
                             const std::string& help, const std::string& fallback) {
  options_.push_back({name, value_name, help, fallback, false});
  return *this;
}

ArgParser& ArgParser::Flag(const std::string& name, const std::string& help) {
  options_.push_back({name, "", help, "", true});
  return *this;
}

ArgParser& ArgParser::Positional(const std::string& name, const std::string& help,
                                 bool required) {
  positionals_.push_back({name, help, required});
  return *this;
}

ArgParser& ArgParser::Epilog(const std::string& text) {
  epilog_ = text;
  return *this;
}

const ArgParser::Spec* ArgParser::FindSpec(const std::string& name) const {
  for (const auto& s : options_)
    if (s.name == name) return &s;
  return nullptr;
}

std::string ArgParser::Help() const {
  std::ostringstream os;
  os << "usage: " << program_;
  if (!options_.empty()) os << " [options]";
  for (const auto& p : positionals_) os << (p.required ? " " : " [") << p.name << (p.required ? "" : "]");
  os << "\n\n" << description_ << "\n";
  if (!positionals_.empty()) {
    os << "\narguments:\n";
    for (const auto& p : positionals_) {
      std::string head = "  " + p.name;
      head.resize(std::max<size_t>(head.size() + 2, 26), ' ');
      os << head << p.help << "\n";
    }
  }
  os << "\noptions:\n";
  for (const auto& s : options_) {
    std::string head = "  --" + s.name + (s.is_flag ? "" : " " + s.value_name);
    head.resize(std::max<size_t>(head.size() + 2, 26), ' ');
    os << head << s.help;
    if (!s.fallback.empty()) os << " (default: " << s.fallback << ")";
    os << "\n";
  }
  os << "  --help                  show this help\n";
  if (!epilog_.empty()) os << "\n" << epilog_ << "\n";
  return os.str();
}

bool ArgParser::Parse(int argc, char** argv) {
  size_t next_positional = 0;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(Help().c_str(), stdout);
      return false;
    }
    if (arg.rfind("--", 0) == 0 && arg.size() > 2) {
      std::string name = arg.substr(2), value;
      bool has_inline = false;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_inline = true;
      }
      const Spec* spec = FindSpec(name);
      if (!spec) throw UsageError("unknown option --" + name + " (see " + program_ + " --help)");
      if (spec->is_flag) {
        if (has_inline) throw UsageError("--" + name + " takes no value");
        values_[name] = "1";
      } else {
        if (!has_inline) {
          if (i + 1 >= argc) throw UsageError("--" + name + " needs a value " + spec->value_name);
          value = argv[++i];
        }
        values_[name] = value;
      }
      continue;
    }
    if (next_positional >= positionals_.size())
      throw UsageError("unexpected argument '" + arg + "' (see " + program_ + " --help)");
    values_[positionals_[next_positional++].name] = arg;
  }
  for (size_t k = next_positional; k < positionals_.size(); ++k)
    if (positionals_[k].required)
      throw UsageError("missing argument " + positionals_[k].name + " (see " + program_ + " --help)");
  return true;
}

bool ArgParser::Has(const std::string& name) const { return values_.count(name) > 0; }

std::optional<std::string> ArgParser::GetOptional(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  if (const Spec* s = FindSpec(name); s && !s->fallback.empty()) return s->fallback;
  return std::nullopt;
}

std::string ArgParser::Get(const std::string& name) const {
  auto v = GetOptional(name);
  if (!v) throw UsageError("missing --" + name);
  return *v;
}

double ArgParser::GetDouble(const std::string& name) const {
  const std::string s = Get(name);
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0') throw UsageError("--" + name + " expects a number, got '" + s + "'");
  return v;
}

long GetIntImpl(const std::string& name, const std::string& s) {
  char* end = nullptr;
  long v = std::strtol(s.c_str(), &end, 10);
  if (end == s.c_str() || *end != '\0') throw UsageError("--" + name + " expects an integer, got '" + s + "'");
  return v;
}

long ArgParser::GetInt(const std::string& name) const { return GetIntImpl(name, Get(name)); }

bool ArgParser::GetFlag(const std::string& name) const { return values_.count(name) > 0; }

}  // namespace sedbridge::app
