#include "scene/fingertip_scene.h"

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
