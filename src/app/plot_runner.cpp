#include "app/plot_runner.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sys/wait.h>

#include "common/resource_path.h"

namespace sedbridge::app {
namespace {

std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

bool HasMatplotlib(const std::string& python) {
  const std::string cmd = Quote(python) + " -c 'import matplotlib' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

}  // namespace

bool RunPlotScript(const std::string& script, const std::vector<std::string>& args) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("SEDBRIDGE_PYTHON")) candidates.push_back(env);
  candidates.push_back("/usr/bin/python3");
  candidates.push_back("python3");
  std::string python;
  for (const auto& c : candidates)
    if ((c.find('/') == std::string::npos || std::filesystem::exists(c)) && HasMatplotlib(c)) {
      python = c;
      break;
    }
  if (python.empty()) {
    std::fprintf(stderr, "plots skipped: no python3 with matplotlib (apt-get install python3-matplotlib)\n");
    return false;
  }
  const std::string path = config::ResolveResource("tools/" + script);
  std::string cmd = Quote(python) + " " + Quote(path);
  for (const auto& a : args) cmd += " " + Quote(a);
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    std::fprintf(stderr, "plot script %s failed (exit %d)\n", script.c_str(), WIFEXITED(rc) ? WEXITSTATUS(rc) : rc);
    return false;
  }
  return true;
}

}  // namespace sedbridge::app
