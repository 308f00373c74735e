#pragma once
// The bridge's fast FE path: Merkel-layer SED for a surface traction that is a linear
// combination of fixed traction fields (one per taxel axis), exact for a linear,
// quasi-static, traction-only scene (fem::LinearResponseBasis). Built once (one sparse
// solve per basis field); a step is then one small dense product plus the SED.

#include <memory>
#include <vector>

#include "fem/linear_response_basis.h"
#include "scene/fingertip_scene.h"

namespace sedbridge::scene {

class ReducedMerkelResponse {
 public:
  /// @param scene        linear elasticity, quasi-static, surface_traction, Merkel output,
  ///                     no contact or tracked bone (checked; std::invalid_argument otherwise)
  /// @param basis_fields traction [Pa] at each of scene.traction()->nodes() (model frame),
  ///                     one 3 x n matrix per basis coefficient
  ReducedMerkelResponse(FingertipScene& scene, const std::vector<Eigen::Matrix3Xd>& basis_fields);

  /// Merkel vertex SED [Pa] for coefficients c (one per basis field); also stored in
  /// scene.merkel()->sed_Pa().
  const Eigen::VectorXd& Evaluate(const Eigen::VectorXd& c);
  int num_basis() const { return basis_->num_basis(); }
  const fem::LinearResponseBasis& basis() const { return *basis_; }

 private:
  FingertipScene& scene_;
  std::unique_ptr<fem::LinearResponseBasis> basis_;
  Eigen::VectorXd element_sed_;
};

}  // namespace sedbridge::scene
