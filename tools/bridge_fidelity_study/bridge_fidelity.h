#pragma once
// Fidelity of the sensor-driven pressure boundary condition (docs/bridge-fidelity.md).
//
// Reference: the object pressed directly onto the fingertip with penalty contact
// (quasi-static, linear elasticity, bone fixed) -> Merkel SED s_ref, and the contact force
// at each skin node. Ideal sensor of pitch h: a grid of h x h taxels tiling the pad plane
// (centred on the origin); each reads the contact force of the nodes whose pad projection
// falls in its cell, divided by h^2 (force-conserving, no sensor mechanics). Bridge: those
// readings -> PressureBoundaryCondition -> the same model under surface traction -> s_bc.
// Error: |s_bc - s_ref|_2 / |s_ref|_2 over the Merkel vertices facing the pad, and the
// ratio of the peaks.

#include <string>
#include <vector>

#include "bridge/traction_field.h"

namespace sedbridge::bridge::fidelity {

struct Case {
  std::string name;         ///< "plane", "sphere", "edge"
  std::string object_yaml;  ///< one object (pad frame), without its motion
  double depth_mm = 1.0;    ///< how far it moves along -z_pad
};

/// The three shipped cases: plane (1.0 mm), sphere R 10 mm (1.0 mm), edge R 1 mm along x (0.5 mm).
std::vector<Case> DefaultCases();

struct Result {
  std::string name;
  double pitch_mm = 0;
  int taxels = 0;
  double contact_force_N = 0;   ///< direct press, total contact force
  double bc_force_N = 0;        ///< applied by the BC
  double ref_max_sed_Pa = 0;
  double bc_max_sed_Pa = 0;
  double rel_l2_error = 0;      ///< |s_bc - s_ref| / |s_ref| (pad-facing Merkel vertices)
  double peak_ratio = 0;        ///< max s_bc / max s_ref
  /// Diagnostic, per case: the contact's own nodal force vectors (lateral parts included)
  /// applied through SurfaceTractionForce exactly (traction solving M t = F, M the
  /// consistent-load matrix): the error left when sampling and interpolation are perfect.
  double exact_nodal_rel_l2_error = 0;
};

/// Runs one case on `model` for each pitch. Slow on B (a contact solve), fast on B_coarse.
std::vector<Result> RunCase(const std::string& model, const Case& c, const std::vector<double>& pitches_mm,
                            NodalLoad nodal_load = NodalLoad::kLumped, int press_steps = 8);

}  // namespace sedbridge::bridge::fidelity
