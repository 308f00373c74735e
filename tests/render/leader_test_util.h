#pragma once
// The leader's finger for the display-on-the-leader tests: B_coarse with face contact, as
// render::DisplayRendering builds it (holes and pins are narrower than the skin-node spacing).

#include <Eigen/Core>

#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render::testing {

inline scene::FingertipComplianceOptions FaceContact() {
  scene::FingertipComplianceOptions options;
  options.face_samples = true;
  return options;
}

struct Leader {
  model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  scene::FingertipCompliance fingertip{model, FaceContact()};
};

inline double RelativeL2(const Eigen::VectorXd& a, const Eigen::VectorXd& reference) {
  return (a - reference).norm() / reference.norm();
}

}  // namespace sedbridge::render::testing
