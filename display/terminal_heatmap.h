#pragma once
// Text rendering of what the finger would feel: the actuator array as a heatmap in the
// terminal (ANSI 256 colours, or plain characters), plus a coarse map of the SED field.

#include <string>
#include <vector>

#include "display/display_command.h"
#include "display/sed_field.h"

namespace sedbridge::display {

struct HeatmapStyle {
  bool color = true;        ///< ANSI 256-colour backgrounds; false = plain ASCII shades
  int cell_width = 6;       ///< characters per actuator cell (>= 4)
  int sed_columns = 24;     ///< width of the SED map in cells of 2 characters (0 = none)
  int sed_rows = 24;        ///< most rows of the SED map (rows follow the field's aspect)
  /// SED shown as full colour [Pa]; 0 = each frame's own peak (then noise looks as strong as
  /// a press). The header line always prints the scale in use.
  double sed_full_scale_Pa = 0;
};

/// Places actuators on a character grid: one column per distinct x, one row per distinct y
/// (tip at the top, larger y first). Works for grids and for sparse explicit layouts.
struct ActuatorLayout {
  std::vector<double> x_mm, y_mm;  ///< actuator sites, pad frame [mm]
  double max = 1;                  ///< value shown as full scale [unit] (the hard max)
  std::string unit;
};

/// Renders one frame. `sed` may be null (no field received yet). Values beyond [0, max] and
/// NaN are shown as such (a viewer must not hide a bad command), never crash the rendering.
std::string RenderHeatmap(const ActuatorLayout& layout, const DisplayCommand& command,
                          const SedField* sed, const HeatmapStyle& style = {});

}  // namespace sedbridge::display
