#include "scene/reduced_merkel_response.h"

#include <stdexcept>

namespace sedbridge::scene {

ReducedMerkelResponse::ReducedMerkelResponse(FingertipScene& scene, const std::vector<Eigen::Matrix3Xd>& fields)
    : scene_(scene) {
  const SceneDescription& d = scene.description();
  if (d.elasticity != fem::ElasticFormulation::kLinear || d.integrator.kind != fem::IntegratorKind::kQuasiStatic ||
      !scene.traction() || !scene.merkel() || scene.contact() || (d.bone && d.bone->motion))
    throw std::invalid_argument(
        "the reduced response needs a linear, quasi-static, traction-only scene with Merkel output and a fixed bone");
  auto& sim = scene.simulation();
  sim.PrepareConstantMatrix();
  fem::SurfaceTractionForce& traction = *scene.traction();
  std::vector<Eigen::VectorXd> loads;
  for (const auto& field : fields) {
    traction.SetNodalTraction(field);
    const Eigen::Matrix3Xd nodal = traction.NodalForces();
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * scene.model().num_soft_nodes());
    for (size_t k = 0; k < traction.nodes().size(); ++k) f.segment<3>(3 * traction.nodes()[k]) = nodal.col(Eigen::Index(k));
    loads.push_back(std::move(f));
  }
  traction.ClearTraction();
  basis_ = std::make_unique<fem::LinearResponseBasis>(scene.elastic(), sim.mutable_solver(), sim.matrix(), loads,
                                                       scene.merkel()->evaluator().elements());
}

const Eigen::VectorXd& ReducedMerkelResponse::Evaluate(const Eigen::VectorXd& c) {
  basis_->ElementSed(c, element_sed_);
  return scene_.merkel()->SetFromElementSed(element_sed_);
}

}  // namespace sedbridge::scene
