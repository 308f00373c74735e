// sedbridge: tactile sensor scans -> fingertip FE model -> Merkel-layer SED -> haptic display.

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "app/arg_parser.h"
#include "app/command.h"
#include "common/config_error.h"

namespace sedbridge::app {

std::vector<Command>& Commands() {
  static std::vector<Command> commands;
  return commands;
}

}  // namespace sedbridge::app

namespace {

void PrintHelp() {
  auto cmds = sedbridge::app::Commands();
  std::sort(cmds.begin(), cmds.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::printf(
      "usage: sedbridge COMMAND [options]\n\n"
      "Turns tactile sensor scans from a follower robot finger into strain energy density\n"
      "(SED) at the Merkel-cell layer of a real-time fingertip FE model, and into commands\n"
      "for a haptic display on the leader's finger.\n\ncommands:\n");
  for (const auto& c : cmds) std::printf("  %-14s %s\n", c.name.c_str(), c.summary.c_str());
  std::printf("\n'sedbridge COMMAND --help' describes a command's options and outputs.\n");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sedbridge::app;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    PrintHelp();
    return argc < 2 ? 2 : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::printf("sedbridge 0.1.0\n");
    return 0;
  }
  for (const auto& c : Commands()) {
    if (c.name == argv[1]) {
      try {
        return c.run(argc - 1, argv + 1);
      } catch (const UsageError& e) {
        std::fprintf(stderr, "sedbridge %s: %s\n", argv[1], e.what());
        return 2;
      } catch (const sedbridge::config::ConfigError& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "sedbridge %s: error: %s\n", argv[1], e.what());
        return 1;
      }
    }
  }
  std::fprintf(stderr, "sedbridge: unknown command '%s' (see sedbridge --help)\n", argv[1]);
  return 2;
}
