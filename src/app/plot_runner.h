#pragma once
// The one way the program starts a Python plot script (tools/*.py): fork + exec, no shell, so
// paths and titles are passed as they are, quotes and all. The Python is the caller's choice,
// else the first with matplotlib of $SEDBRIDGE_PYTHON, /usr/bin/python3 (Debian's
// python3-matplotlib) and python3 on PATH.

#include <string>
#include <vector>

namespace sedbridge::app {

struct PlotResult {
  bool ok = false;
  int exit_code = -1;   ///< the script's exit status (127: could not start; -1: no python, or killed)
  std::string message;  ///< why it failed ("" when ok)
};

/// Runs `PYTHON tools/<script> args...` and waits for it; its output goes to this process's
/// stdout and stderr.
/// @param script  file name under tools/ (found with config::ResolveResource)
/// @param args    arguments after the script path
/// @param python  interpreter to use as given; "" = the first with matplotlib (see above)
PlotResult RunPythonScript(const std::string& script, const std::vector<std::string>& args,
                           const std::string& python = "");

/// RunPythonScript for the optional plots of a command: on failure prints why on stderr and
/// returns false. Plots are a convenience: the CSVs they are drawn from are written first.
bool RunPlotScript(const std::string& script, const std::vector<std::string>& args);

}  // namespace sedbridge::app
