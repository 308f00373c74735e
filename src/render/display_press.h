#pragma once
// A press by a display: the leader's pad resting on the display at its preload, the
// actuators at `commands`, solved by full contact on the leader's FE model
// (DisplayOnLeader::Press, the compliance method with face contact, as the display rendering
// builds it): "what does this command do to the finger?". `sedbridge press` runs it for a
// scene with a `display` section (scene::DisplayLoadSection, config/scenes/README.md) and
// writes what a press writes (merkel_sed.csv, a VTU) plus the commands and the preload.

#include <Eigen/Core>
#include <string>

#include "display/display_profile.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {

struct DisplayPressResult {
  /// Merkel SED [Pa] with the actuators at the commands (preload included), per vertex of
  /// the leader's Merkel layer (model.merkel_nodes order): DisplayOnLeader::Press's answer.
  Eigen::VectorXd sed_Pa;
  /// Merkel SED [Pa] of the pad at the preload with every actuator off.
  Eigen::VectorXd preload_sed_Pa;
  double preload_force_N = 0;  ///< the pad's force on the display at rest [N]
};

/// Presses `profile`'s display on `leader` (build it with DisplayLeaderOptions) with
/// `commands` (one per actuator, in [0, the actuator's safety maximum], the profile's
/// unit). Throws DisplayDoesNotFitPad (render/leader_pad.h) for footprints off the pad,
/// std::invalid_argument for a display without a mechanical load or wrong commands,
/// std::runtime_error when a contact solve fails.
DisplayPressResult PressDisplay(scene::FingertipCompliance& leader, const display::DisplayProfile& profile,
                                const Eigen::VectorXd& commands);

/// In `dir` (created): merkel_sed.csv (vertex = Gmsh node tag, x_mm, y_mm, z_mm pad frame,
/// sed_Pa: with the commands, as a press writes it), display_added_sed.csv (the same
/// vertices, the SED the commands add to the preloaded pad), display_commands.csv
/// (actuator, x_mm, y_mm, command in the profile's unit), display_press.csv (model,
/// display, unit, preload force, max SED with and without the commands) and
/// display_press.vtu (the rest mesh: the compliance method solves the pad's and the Merkel
/// layer's displacements, not every node's; merkel_sed_Pa and display_added_sed_Pa).
void WriteDisplayPress(const scene::FingertipCompliance& leader, const display::DisplayProfile& profile,
                       const Eigen::VectorXd& commands, const DisplayPressResult& result, const std::string& dir);

}  // namespace sedbridge::render
