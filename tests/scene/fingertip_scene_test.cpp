#include "scene/fingertip_scene.h"

#include <algorithm>
#include <gtest/gtest.h>

#include "fem/bone_coupling_force.h"
#include "fem/pseudo_friction_force.h"

namespace sedbridge::scene {
namespace {

TEST(FingertipScene, BuildsOnlyTheListedEffects) {
  const SceneDescription traction_only = ParseSceneDescription(
      "model: B_coarse\nbone: {mode: fixed}\nsurface_traction: true\noutputs: {merkel_sed: false}\n", "t.yaml");
  FingertipScene a(traction_only);
  EXPECT_EQ(a.BuiltEffects(), (std::vector<std::string>{"elastic_corotational", "bone_coupling", "surface_traction"}));
  EXPECT_EQ(a.contact(), nullptr);
  EXPECT_EQ(a.merkel(), nullptr);
  EXPECT_NE(a.traction(), nullptr);

  const SceneDescription press = ParseSceneDescription(
      "model: B_coarse\nelasticity: linear\nbone: {}\ncontact:\n  objects: [{shape: sphere, radius_mm: 5, position_mm: [0,0,5]}]\n"
      "friction: {anisotropy: 0.5}\n",
      "p.yaml");
  FingertipScene b(press);
  EXPECT_EQ(b.BuiltEffects(),
            (std::vector<std::string>{"elastic_linear", "bone_coupling", "penalty_contact", "pseudo_friction"}));
  EXPECT_NE(b.merkel(), nullptr);
  EXPECT_EQ(b.traction(), nullptr);
}

TEST(FingertipScene, TractionOnlyLinearSceneAssemblesOnce) {
  const SceneDescription d = ParseSceneDescription(
      "model: B_coarse\nelasticity: linear\nbone: {}\nsurface_traction: true\ndynamics: {dt_s: 0.001}\n", "c.yaml");
  FingertipScene s(d);
  EXPECT_TRUE(s.simulation().constant_matrix());
  // Uniform pressure on the pad-facing skin: the finger is pushed, SED appears, all finite.
  auto* traction = s.traction();
  Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, Eigen::Index(traction->nodes().size()));
  const Eigen::Vector3d z_pad = s.model().pad_frame.model_from_pad.linear().col(2);
  for (Eigen::Index k = 0; k < t.cols(); ++k) {
    const Eigen::Vector3d p = s.model().pad_frame.ToPad(traction->node_rest_positions_m().col(k)) * 1e3;
    if (p.z() > -1.0 && std::abs(p.x()) < 4 && std::abs(p.y()) < 4) t.col(k) = -2000.0 * z_pad;
  }
  traction->SetNodalTraction(t);
  for (int i = 0; i < 20; ++i) {
    const auto r = s.Step();
    ASSERT_TRUE(r.finite);
    ASSERT_TRUE(r.converged);
  }
  EXPECT_GT(s.merkel()->sed_Pa().maxCoeff(), 1.0);
  EXPECT_TRUE(s.merkel()->sed_Pa().allFinite());
}

}  // namespace
}  // namespace sedbridge::scene

namespace sedbridge::scene {
namespace {

TEST(FingertipScene, TrackedBoneCarriesTheFingerRigidly) {
  // The bone follows a tracked pose (1 mm along x, 10 deg about z, over 0.1 s) and holds:
  // with nothing touching, the soft tissue must end up moved rigidly with it (zero SED).
  const SceneDescription d = ParseSceneDescription(
      "model: B_coarse\nbone:\n  mode: tracked\n  stiffness_N_m: 200\n  motion:\n    keyframes:\n"
      "      - {t_s: 0.0, offset_mm: [0, 0, 0]}\n      - {t_s: 0.1, offset_mm: [1, 0, 0], rpy_deg: [0, 0, 10]}\n"
      "dynamics: {integrator: backward_euler, dt_s: 0.005}\nsolver: {type: pcg_warp, tolerance: 1.0e-10}\n",
      "tracked.yaml");
  FingertipScene s(d);
  for (int k = 0; k < 200; ++k) ASSERT_TRUE(s.Step().finite);
  const Eigen::Isometry3d pose = d.bone->motion->Pose(1.0) * d.bone->motion->Pose(0.0).inverse();
  const auto& x = s.simulation().positions_m();
  double max_error = 0;
  for (int i = 0; i < s.model().num_soft_nodes(); ++i)
    max_error = std::max(max_error, (x.segment<3>(3 * i) - pose * s.model().soft.rest_positions_m.col(i)).norm());
  EXPECT_LT(max_error, 1e-6);  // 1 um after settling, for a 1 mm / 10 deg move
  EXPECT_GT((x.segment<3>(0) - s.model().soft.rest_positions_m.col(0)).norm(), 5e-4);  // it did move
  EXPECT_LT(s.merkel()->sed_Pa().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace sedbridge::scene

namespace sedbridge::scene {
namespace {

TEST(FingertipScene, NodalPressureTermIsBuiltOnlyWhenAsked) {
  const std::string base = "model: B_coarse\nbone: {}\nsurface_traction: true\ndynamics: {dt_s: 0.001}\n"
                           "solver: {type: pcg_jacobi, max_iterations: 2000}\n";
  FingertipScene plain(ParseSceneDescription(base, "p.yaml"));
  EXPECT_EQ(plain.nodal_pressure(), nullptr);
  FingertipScene s(ParseSceneDescription(base + "elasticity: nodal_pressure\n", "n.yaml"));
  ASSERT_NE(s.nodal_pressure(), nullptr);
  const auto effects = s.BuiltEffects();
  EXPECT_NE(std::find(effects.begin(), effects.end(), "nodal_pressure"), effects.end());
  auto* traction = s.traction();
  Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, Eigen::Index(traction->nodes().size()));
  const Eigen::Vector3d z_pad = s.model().pad_frame.model_from_pad.linear().col(2);
  for (Eigen::Index k = 0; k < t.cols(); ++k) {
    const Eigen::Vector3d p = s.model().pad_frame.ToPad(traction->node_rest_positions_m().col(k)) * 1e3;
    if (p.z() > -1.0 && std::abs(p.x()) < 4 && std::abs(p.y()) < 4) t.col(k) = -2000.0 * z_pad;
  }
  traction->SetNodalTraction(t);
  for (int i = 0; i < 10; ++i) {
    const auto r = s.Step();
    ASSERT_TRUE(r.finite);
    ASSERT_TRUE(r.converged);
  }
  EXPECT_GT(s.merkel()->sed_Pa().maxCoeff(), 1.0);
  EXPECT_TRUE(s.merkel()->sed_Pa().allFinite());
}

}  // namespace
}  // namespace sedbridge::scene
