#pragma once
// The tests that run the built programs: start one as a child process with its output in a
// file, wait (with a time limit) for it to end or for something it writes, read what it
// wrote, or run a shell command for its output and exit status. One copy for every such test.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace sedbridge::testing {

/// How often the waits below look again.
constexpr std::chrono::milliseconds kChildPollPeriod{20};

/// Starts args[0] (a path, not looked up in PATH) with args[1..] in a child process, its
/// stdout and stderr into `output_path` (truncated), or left as the test's own when it is "".
/// Returns the child's pid (-1 when fork failed; a child that cannot exec exits 127).
inline pid_t Spawn(const std::vector<std::string>& args, const std::string& output_path = "") {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!output_path.empty()) {
      const int fd = ::open(output_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

/// Looks at `done` every kChildPollPeriod for up to `limit_s`; true once it holds.
template <typename Pred>
bool WaitFor(Pred done, double limit_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(kChildPollPeriod);
  }
  return false;
}

/// Waits up to `limit_s` for child `pid` to end: its exit status, -2 when a signal ended it,
/// or -1 when it did not end in time (then it is killed with SIGKILL and reaped).
/// `between`: called between looks instead of sleeping kChildPollPeriod, for a test that must
/// keep working meanwhile (handle LCM messages, publish); it should take about that long.
inline int WaitExit(pid_t pid, double limit_s, const std::function<void()>& between = {}) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -2;
    if (between)
      between();
    else
      std::this_thread::sleep_for(kChildPollPeriod);
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

/// The whole text of a file ("" when it cannot be read): a child's output, a file written.
inline std::string Slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

struct ShellResult {
  std::string output;  ///< stdout and stderr together
  int status = -1;     ///< exit status; -1 when it did not exit normally (or could not start)
};

/// Runs `command` with /bin/sh and waits for it.
inline ShellResult RunShell(const std::string& command) {
  ShellResult r;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  while (size_t n = std::fread(buf.data(), 1, buf.size(), p)) r.output.append(buf.data(), n);
  const int status = ::pclose(p);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace sedbridge::testing
