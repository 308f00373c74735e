#include "scene/reduced_merkel_response.h"

#include <gtest/gtest.h>

#include <random>

namespace sedbridge::scene {
namespace {

const char* kScene =
    "model: B_coarse\nelasticity: linear\nbone: {mode: fixed}\nsurface_traction: true\n"
    "dynamics: {integrator: quasi_static, steps: 1, newton_iterations: 1}\n";

// Three pressure patches and one shear patch on the pad.
std::vector<Eigen::Matrix3Xd> Patches(const FingertipScene& s) {
  const auto* traction = s.traction();
  const Eigen::Matrix3d pad = s.model().pad_frame.model_from_pad.linear();
  std::vector<Eigen::Matrix3Xd> fields;
  const double centres[4][2] = {{0, 0}, {3, 1}, {-2, 3}, {0, 1}};
  for (int j = 0; j < 4; ++j) {
    Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, Eigen::Index(traction->nodes().size()));
    for (Eigen::Index k = 0; k < t.cols(); ++k) {
      const Eigen::Vector3d p = s.model().pad_frame.ToPad(traction->node_rest_positions_m().col(k)) * 1e3;
      if (p.z() < -1.5 || std::hypot(p.x() - centres[j][0], p.y() - centres[j][1]) > 2.5) continue;
      t.col(k) = j < 3 ? Eigen::Vector3d(-pad.col(2)) : Eigen::Vector3d(pad.col(0));  // 1 Pa inward / lateral
    }
    fields.push_back(t);
  }
  return fields;
}

TEST(ReducedMerkelResponse, MatchesTheFullQuasiStaticSolve) {
  FingertipScene reduced_scene(ParseSceneDescription(kScene, "r"));
  const auto fields = Patches(reduced_scene);
  ReducedMerkelResponse reduced(reduced_scene, fields);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 3000);
  const Eigen::VectorXd c = Eigen::VectorXd::NullaryExpr(4, [&]() { return u(rng); });
  const Eigen::VectorXd fast = reduced.Evaluate(c);

  FingertipScene full(ParseSceneDescription(kScene, "f"));
  Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, fields[0].cols());
  for (int j = 0; j < 4; ++j) t += c[j] * fields[size_t(j)];
  full.traction()->SetNodalTraction(t);
  ASSERT_TRUE(full.Step().converged);
  const Eigen::VectorXd& reference = full.merkel()->sed_Pa();
  ASSERT_EQ(fast.size(), reference.size());
  EXPECT_GT(reference.maxCoeff(), 1.0);
  EXPECT_LT((fast - reference).cwiseAbs().maxCoeff(), 1e-8 * reference.maxCoeff());
}

TEST(ReducedMerkelResponse, RefusesScenesItCannotRepresent) {
  FingertipScene corotational(ParseSceneDescription(
      "model: B_coarse\nbone: {}\nsurface_traction: true\ndynamics: {integrator: quasi_static}\n", "c"));
  EXPECT_THROW(ReducedMerkelResponse(corotational, {}), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::scene
