#pragma once
// Subcommands of the `sedbridge` program register themselves here; each lives in its own
// src/app/*_command.cpp so that stages can add commands without touching a shared list.

#include <string>
#include <vector>

namespace sedbridge::app {

struct Command {
  std::string name;     ///< e.g. "press"
  std::string summary;  ///< one line for `sedbridge --help`
  int (*run)(int argc, char** argv);  ///< argv[0] is the command name; returns exit code
};

std::vector<Command>& Commands();

struct CommandRegistrar {
  explicit CommandRegistrar(Command c) { Commands().push_back(std::move(c)); }
};

}  // namespace sedbridge::app

#define SEDBRIDGE_COMMAND(ident, name, summary, fn) \
  static ::sedbridge::app::CommandRegistrar ident##_registrar{{name, summary, fn}}
