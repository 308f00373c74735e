#pragma once
// The one call the bridge pipeline makes into the FE side: taxel values in, Merkel-layer SED
// out. Kept narrow on purpose so that a faster implementation (e.g. a reduced linear
// operator built from PressureBoundaryCondition::applied_weights()) can replace the scene-based one
// without touching the pipeline.

#include <Eigen/Core>
#include <string>

#include "bridge/fe_frame.h"
#include "bridge/taxel_values.h"
#include "contact/contact_estimate.h"
#include "fem/step_report.h"

namespace sedbridge::bridge {

/// Result of one FE step. References stay valid until the next Step().
struct MerkelSedResult {
  bool ok = false;                   ///< false: no usable SED this step (see `error`)
  std::string error;                 ///< why not ok
  const Eigen::VectorXd* sed_Pa = nullptr;  ///< SED per Merkel vertex [Pa] (only when ok)
  fem::StepReport report;            ///< solver iterations, residual, convergence
  double applied_force_N = 0;        ///< applied load along -z_pad (pressing force) [N]
};

class FeStep {
 public:
  virtual ~FeStep() = default;
  /// Applies `values` (finite, profile taxel count) as the load and solves one step.
  virtual const MerkelSedResult& Step(const TaxelValues& values) = 0;
  /// Merkel vertices' rest positions in the pad frame [mm], 3 x #vertices.
  virtual const Eigen::Matrix3Xd& merkel_rest_pad_mm() const = 0;
  /// Model id for messages (e.g. "B").
  virtual const std::string& model_id() const = 0;
  /// One line, e.g. "scene B (fast): 1642 soft nodes, ldlt".
  virtual std::string Describe() const = 0;
  /// One line of implementation counters for the run summary ("" = nothing to say).
  virtual std::string CountersLine() const { return ""; }
  /// The last step's reconstructed contact (leader pad frame) and how it was answered, or
  /// null when this step does not reconstruct contacts (lcm/contact_estimate_message.h puts
  /// it on the wire).
  virtual const contact::ContactReport* contact_report() const { return nullptr; }
  /// The deformed mesh and its fields after the last Step() (rest before the first), for
  /// VTU frames. False when this step keeps no full displacement field.
  virtual bool Frame(FeFrame* frame) const {
    (void)frame;
    return false;
  }
};

}  // namespace sedbridge::bridge
