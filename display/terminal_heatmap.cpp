#include "display/terminal_heatmap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace sedbridge::display {
namespace {

// 0..1 -> an ANSI 256-colour index on a dark-blue -> red -> yellow ramp.
int HeatColor(double t) {
  static const int kRamp[] = {17, 18, 19, 20, 54, 90, 126, 162, 198, 203, 209, 215, 221, 227, 229};
  constexpr int n = sizeof(kRamp) / sizeof(kRamp[0]);
  if (!(t >= 0)) t = 0;
  if (t > 1) t = 1;
  return kRamp[std::min(n - 1, static_cast<int>(t * (n - 1) + 0.5))];
}

char Shade(double t) {
  static const char kShades[] = " .:-=+*#%@";
  if (!(t >= 0)) return '?';
  if (t > 1) t = 1;
  return kShades[static_cast<int>(t * 9 + 0.5)];
}

// Distinct coordinates, merged within 1 µm, sorted ascending.
std::vector<double> Distinct(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  std::vector<double> out;
  for (double x : v)
    if (std::isfinite(x) && (out.empty() || x - out.back() > 1e-3)) out.push_back(x);
  return out;
}

int IndexOf(const std::vector<double>& sorted, double x) {
  for (std::size_t i = 0; i < sorted.size(); ++i)
    if (std::abs(sorted[i] - x) <= 1e-3) return static_cast<int>(i);
  return -1;
}

std::string Cell(double value, double max, const HeatmapStyle& s) {
  char text[32];
  if (std::isnan(value)) std::snprintf(text, sizeof text, "NaN");
  else if (std::abs(value) >= 1000) std::snprintf(text, sizeof text, "%.0e", value);
  else std::snprintf(text, sizeof text, value < 10 ? "%.2f" : "%.1f", value);
  std::string t(text);
  const int w = std::max(4, s.cell_width);
  if (static_cast<int>(t.size()) > w - 1) t = t.substr(0, w - 1);
  const int pad_left = (w - static_cast<int>(t.size())) / 2;
  std::string body = std::string(pad_left, ' ') + t;
  body += std::string(w - body.size(), ' ');
  const double frac = max > 0 ? value / max : 0;
  if (!s.color) {
    body[0] = Shade(frac);
    return "[" + body + "]";
  }
  const int bg = HeatColor(frac);
  const int fg = frac > 0.6 ? 16 : 231;  // dark text on bright cells
  const bool over = value > max || value < 0 || std::isnan(value);
  return "\033[48;5;" + std::to_string(bg) + ";38;5;" + std::to_string(over ? 196 : fg) + "m" +
         body + "\033[0m";
}

void RenderSed(std::ostringstream& os, const ActuatorLayout& layout, const SedField& sed,
               const HeatmapStyle& s) {
  if (s.sed_columns <= 0 || s.sed_rows <= 0) return;
  const std::size_t n = sed.sed_Pa.size();
  if (sed.x_mm.size() != n || sed.y_mm.size() != n) {
    os << "SED field: inconsistent lengths (" << sed.x_mm.size() << ", " << sed.y_mm.size() << ", "
       << n << ")\n";
    return;
  }
  // Window: the actuator array's extent plus one pitch-ish margin.
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (std::size_t i = 0; i < layout.x_mm.size(); ++i) {
    x0 = std::min(x0, layout.x_mm[i]);
    x1 = std::max(x1, layout.x_mm[i]);
    y0 = std::min(y0, layout.y_mm[i]);
    y1 = std::max(y1, layout.y_mm[i]);
  }
  if (!(x0 <= x1)) x0 = -5, x1 = 5, y0 = -5, y1 = 5;
  x0 -= 2, x1 += 2, y0 -= 2, y1 += 2;
  // Each cell shows the largest SED within ~one cell of its centre, so a coarse vertex
  // spacing does not leave holes.
  // Square cells on screen (a cell is two characters wide, one line tall).
  const int rows = std::clamp(static_cast<int>(std::lround(s.sed_columns * (y1 - y0) / (x1 - x0))),
                              2, s.sed_rows);
  const double cw = (x1 - x0) / s.sed_columns, chh = (y1 - y0) / rows;
  const double r2 = 0.5625 * std::max(cw * cw, chh * chh) * 2;  // (0.75 * cell diagonal)^2
  std::vector<double> bins(static_cast<std::size_t>(s.sed_columns * rows), 0.0);
  double peak = 0, peak_x = 0, peak_y = 0;
  std::size_t bad = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const double e = sed.sed_Pa[v];
    if (!std::isfinite(e) || !std::isfinite(sed.x_mm[v]) || !std::isfinite(sed.y_mm[v])) {
      ++bad;
      continue;
    }
    if (sed.z_mm.size() == n && sed.z_mm[v] < -6) continue;  // far side of the finger
    if (e > peak) peak = e, peak_x = sed.x_mm[v], peak_y = sed.y_mm[v];
    const int c0 = static_cast<int>(std::floor((sed.x_mm[v] - x0) / cw)) - 1;
    const int r0 = static_cast<int>(std::floor((y1 - sed.y_mm[v]) / chh)) - 1;
    for (int r = std::max(0, r0); r <= std::min(rows - 1, r0 + 2); ++r) {
      for (int c = std::max(0, c0); c <= std::min(s.sed_columns - 1, c0 + 2); ++c) {
        const double dx = x0 + (c + 0.5) * cw - sed.x_mm[v], dy = y1 - (r + 0.5) * chh - sed.y_mm[v];
        if (dx * dx + dy * dy > r2) continue;
        double& b = bins[static_cast<std::size_t>(r * s.sed_columns + c)];
        b = std::max(b, e);
      }
    }
  }
  const bool fixed = s.sed_full_scale_Pa > 0;
  const double scale = fixed ? s.sed_full_scale_Pa : peak;
  char head[220];
  std::snprintf(head, sizeof head,
                "Merkel-layer SED (max per cell, x %.1f..%.1f mm, y %.1f..%.1f mm): peak %.3g Pa at "
                "(%.1f, %.1f) mm; colour scale 0..%.3g Pa (%s)%s\n",
                x0, x1, y0, y1, peak, peak_x, peak_y, scale, fixed ? "fixed" : "this frame's peak",
                bad ? "  [non-finite values!]" : "");
  os << head;
  for (int r = 0; r < rows; ++r) {
    os << "  ";
    for (int c = 0; c < s.sed_columns; ++c) {
      const double t = scale > 0 ? std::min(1.0, bins[static_cast<std::size_t>(r * s.sed_columns + c)] / scale) : 0;
      if (s.color) os << "\033[48;5;" << HeatColor(t) << "m  \033[0m";
      else os << Shade(t) << Shade(t);
    }
    os << "\n";
  }
}

}  // namespace

std::string RenderHeatmap(const ActuatorLayout& layout, const DisplayCommand& command,
                          const SedField* sed, const HeatmapStyle& style) {
  std::ostringstream os;
  char head[256];
  std::snprintf(head, sizeof head, "%s  seq %lld  t=%.3f s  unit %s  full scale %.3g%s%s%s%s\n",
                command.display_id.c_str(), static_cast<long long>(command.sequence),
                command.utime * 1e-6, layout.unit.c_str(), layout.max,
                command.clamped ? "  [CLAMPED]" : "", command.stale ? "  [STALE]" : "",
                command.fault ? "  [FAULT]" : "", command.shutdown ? "  [SHUTDOWN]" : "");
  os << head;
  const std::size_t n = std::min(layout.x_mm.size(), layout.y_mm.size());
  if (command.value.size() != n) {
    os << "command has " << command.value.size() << " values, profile has " << n
       << " actuators: wrong profile?\n";
  }
  std::vector<double> xs = Distinct(layout.x_mm), ys = Distinct(layout.y_mm);
  std::reverse(ys.begin(), ys.end());  // tip (larger y) on top
  std::map<std::pair<int, int>, std::size_t> at;
  for (std::size_t i = 0; i < n; ++i) at[{IndexOf(ys, layout.y_mm[i]), IndexOf(xs, layout.x_mm[i])}] = i;
  os << "  tip ^\n";
  for (int r = 0; r < static_cast<int>(ys.size()); ++r) {
    os << "  ";
    for (int c = 0; c < static_cast<int>(xs.size()); ++c) {
      auto it = at.find({r, c});
      if (it == at.end() || it->second >= command.value.size()) os << std::string(style.cell_width + (style.color ? 0 : 2), ' ');
      else os << Cell(command.value[it->second], layout.max, style);
    }
    os << "\n";
  }
  os << "  x ->\n";
  if (sed) RenderSed(os, layout, *sed, style);
  return os.str();
}

}  // namespace sedbridge::display
