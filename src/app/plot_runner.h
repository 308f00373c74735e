#pragma once
// Runs the matplotlib scripts in tools/ with a Python that has matplotlib: $SEDBRIDGE_PYTHON,
// else /usr/bin/python3 (Debian's python3-matplotlib), else python3 on PATH.

#include <string>
#include <vector>

namespace sedbridge::app {

/// Runs tools/<script> with `args`. Returns true on success; on failure prints why (no
/// python, no matplotlib, script error) and returns false. Plots are a convenience: the
/// CSVs they are drawn from are always written first.
bool RunPlotScript(const std::string& script, const std::vector<std::string>& args);

}  // namespace sedbridge::app
