#include "app/plot_runner.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "common/resource_path.h"

namespace sedbridge::app {
namespace {

// Exit status of a child that could not exec its program (the shell's convention).
constexpr int kCannotExecStatus = 127;

// Runs argv[0] (searched on PATH) with `argv` and returns its exit status (kCannotExecStatus
// when it could not start, -1 when it was killed). `quiet` sends its output to /dev/null.
int RunProcess(std::vector<std::string> argv, bool quiet) {
  std::fflush(nullptr);  // the child must not write our buffered output a second time
  const pid_t pid = ::fork();
  if (pid < 0) return kCannotExecStatus;
  if (pid == 0) {
    if (quiet) {
      const int null_fd = ::open("/dev/null", O_WRONLY);
      if (null_fd >= 0) ::dup2(null_fd, STDOUT_FILENO), ::dup2(null_fd, STDERR_FILENO);
    }
    std::vector<char*> argv_c;
    for (std::string& a : argv) argv_c.push_back(a.data());
    argv_c.push_back(nullptr);
    ::execvp(argv_c[0], argv_c.data());
    ::_exit(kCannotExecStatus);
  }
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

bool HasMatplotlib(const std::string& python) {
  return RunProcess({python, "-c", "import matplotlib"}, /*quiet=*/true) == 0;
}

// "" when none of the candidates has matplotlib.
std::string FindPythonWithMatplotlib() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("SEDBRIDGE_PYTHON")) candidates.push_back(env);
  candidates.push_back("/usr/bin/python3");
  candidates.push_back("python3");
  for (const auto& c : candidates)
    if ((c.find('/') == std::string::npos || std::filesystem::exists(c)) && HasMatplotlib(c)) return c;
  return "";
}

}  // namespace

PlotResult RunPythonScript(const std::string& script, const std::vector<std::string>& args,
                           const std::string& python) {
  PlotResult result;
  const std::string interpreter = python.empty() ? FindPythonWithMatplotlib() : python;
  if (interpreter.empty()) {
    result.message = "no python3 with matplotlib (apt-get install python3-matplotlib)";
    return result;
  }
  std::vector<std::string> argv = {interpreter, config::ResolveResource("tools/" + script)};
  argv.insert(argv.end(), args.begin(), args.end());
  result.exit_code = RunProcess(argv, /*quiet=*/false);
  result.ok = result.exit_code == 0;
  if (result.exit_code == kCannotExecStatus)
    result.message = "cannot run " + interpreter;
  else if (!result.ok)
    result.message = "plot script " + script + " failed (exit " + std::to_string(result.exit_code) + ")";
  return result;
}

bool RunPlotScript(const std::string& script, const std::vector<std::string>& args) {
  const PlotResult result = RunPythonScript(script, args);
  if (!result.ok) std::fprintf(stderr, "plots skipped: %s\n", result.message.c_str());
  return result.ok;
}

}  // namespace sedbridge::app
