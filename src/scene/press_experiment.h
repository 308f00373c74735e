#pragma once
// The paper's press experiment (Sec. IV-A) on any scene with a contact object: step the
// scene, record force / displacement / contact area per step, keep the Merkel SED of
// every step, and pick the step whose force is closest to a target (1.0 N).
// Writes the output contract of `sedbridge press` (tools read these names).

#include <functional>
#include <string>
#include <vector>

#include "scene/fingertip_scene.h"

namespace sedbridge::scene {

struct PressStepRecord {
  int step = 0;                 ///< 1-based
  double t_s = 0;
  double displacement_mm = 0;   ///< travel of the first contact object from t = 0
  double force_N = 0;           ///< |sum of contact spring forces|
  double contact_area_mm2 = 0;  ///< skin area of nodes in contact
  double max_merkel_sed_Pa = 0;
  fem::StepReport report;
  double wall_ms = 0;           ///< time the step took (FE step + SED)
};

struct PressOptions {
  double target_force_N = 1.0;  ///< the paper compares SED at 1.0 N
  double path_y_mm = 2.0;       ///< path plot along x at this y (pad frame)
  double path_half_width_mm = 8.0;
  double path_step_mm = 0.1;
  std::string vtu_dir;          ///< write VTU frames here when the scene asks (empty = none)
  std::function<void(const PressStepRecord&)> on_step;  ///< progress
};

struct PressResult {
  std::vector<PressStepRecord> steps;
  int selected = -1;                        ///< index into steps (force closest to target)
  std::vector<Eigen::VectorXd> merkel_sed;  ///< per step, per Merkel vertex [Pa]
  std::vector<PathSample> path;             ///< at the selected step
  double selected_max_sed_Pa = 0;
};

PressResult RunPress(FingertipScene& scene, const PressOptions& options);

/// force_displacement.csv, merkel_sed.csv, sed_path.csv (the figure contract),
/// merkel_sed_step.csv (model name and the step, displacement [mm], force [N] and max SED [Pa]
/// the map and path show) and step_timing.csv in `dir` (created if needed).
void WritePressCsv(const FingertipScene& scene, const PressResult& result, const std::string& dir);

}  // namespace sedbridge::scene
