#pragma once
// The Merkel-cell layer (epidermis-dermis interface): vertex SED each step (paper eq. 1,
// vertex = mean of adjacent elements), rest positions in the pad frame, and the paper's
// path plot (SED along x at fixed y on the pad-facing side).

#include <Eigen/Core>
#include <vector>

#include "fem/strain_energy_density.h"
#include "scene/merkel_side.h"
#include "model/fingertip_model.h"

namespace sedbridge::scene {

struct PathSample {
  double x_mm = 0;
  double sed_Pa = 0;
};

class MerkelLayer {
 public:
  /// Both arguments must outlive the layer.
  /// `nodal`: the scene's nodal pressure term, if any (SED with the smoothed pressure).
  /// `side`: the elements a vertex averages (merkel_side.h): both sides of the interface, or
  /// only those of the model's material named "epidermis" / "dermis". Throws
  /// std::invalid_argument when the model has no material of that name.
  MerkelLayer(const model::FingertipModel& model, const fem::ElasticTetForce& elastic,
              const fem::NodalPressureTetForce* nodal = nullptr, MerkelSide side = MerkelSide::kBoth);

  /// Evaluates vertex SED [Pa] at positions x (3 * #soft nodes); returns sed_Pa().
  const Eigen::VectorXd& Evaluate(const Eigen::VectorXd& x_m);
  const Eigen::VectorXd& sed_Pa() const { return sed_Pa_; }

  /// Soft node index of each Merkel vertex (= model.merkel_nodes).
  const std::vector<int>& nodes() const { return evaluator_.vertices(); }
  /// Nodes of the tets whose SED the vertices average: the only positions Evaluate reads.
  const std::vector<int>& element_nodes() const { return evaluator_.element_nodes(); }
  /// Rest position of each vertex in the pad frame [mm], 3 x #vertices.
  const Eigen::Matrix3Xd& rest_pad_mm() const { return rest_pad_mm_; }
  /// 1 where the layer faces the pad (outward normal . z_pad > 0), else 0.
  const std::vector<int>& facing_pad() const { return facing_pad_; }

  /// SED along x at y = y_mm on the pad-facing sheet, linear inside each triangle,
  /// sampled every step_mm in [x_min_mm, x_max_mm]; x where the line leaves the sheet
  /// is skipped. `sed_Pa` is per vertex (e.g. sed_Pa()).
  std::vector<PathSample> SamplePath(const Eigen::VectorXd& sed_Pa, double y_mm, double x_min_mm,
                                     double x_max_mm, double step_mm) const;

 private:
  std::vector<char> side_mask_;  // before evaluator_, which reads it
  fem::VertexSedEvaluator evaluator_;
  Eigen::VectorXd sed_Pa_;
  Eigen::Matrix3Xd rest_pad_mm_;
  std::vector<int> facing_pad_;
  std::vector<std::array<int, 3>> pad_triangles_;  // local vertex ids, facing the pad
};

}  // namespace sedbridge::scene
