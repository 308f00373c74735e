#include "sensors/taxel_heatmap.h"

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/resource_path.h"

namespace sedbridge::sensors {

void WriteTaxelCsv(const SensorProfile& profile, const Scan& scan, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "taxel,x_mm,y_mm,pressure_kPa,shear_x_kPa,shear_y_kPa,valid\n";
  for (int i = 0; i < scan.num_taxels && i < profile.taxel_count; ++i) {
    const double sx = scan.shear_x_Pa.empty() ? 0.0 : scan.shear_x_Pa[i];
    const double sy = scan.shear_y_Pa.empty() ? 0.0 : scan.shear_y_Pa[i];
    out << i << ',' << profile.taxels[i].x_mm << ',' << profile.taxels[i].y_mm << ','
        << scan.pressure_Pa[i] * 1e-3 << ',' << sx * 1e-3 << ',' << sy * 1e-3 << ','
        << int(scan.valid[i]) << '\n';
  }
  if (!out) throw std::runtime_error("error writing " + path);
}

namespace {
std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

PlotResult PlotTaxelHeatmap(const SensorProfile& profile, const std::string& csv,
                            const std::string& png, const std::string& title) {
  const std::string script = config::ResolveResource("tools/plot_taxels.py");
  if (!std::filesystem::exists(script))
    return {false, "plot script tools/plot_taxels.py not found (set SEDBRIDGE_ROOT)"};
  std::string python = "/usr/bin/python3";
  if (!std::filesystem::exists(python)) python = "python3";
  char size[64];
  std::snprintf(size, sizeof size, "%g %g", profile.taxel_width_mm, profile.taxel_height_mm);
  const std::string cmd = Quote(python) + " " + Quote(script) + " " + Quote(csv) + " " + Quote(png) +
                          " --title " + Quote(title) + " --size-mm " + size + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return {false, "cannot start " + python};
  std::string output;
  char buf[256];
  while (std::fgets(buf, sizeof buf, pipe)) output += buf;
  const int status = pclose(pipe);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  while (!output.empty() && output.back() == '\n') output.pop_back();
  if (code == 0) return {true, "wrote " + png};
  if (code == 127) return {false, python + " not found: install python3 and python3-matplotlib"};
  return {false, output.empty() ? "plot script failed with status " + std::to_string(code) : output};
}

}  // namespace sedbridge::sensors
