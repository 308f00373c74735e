// The Merkel layer on model B_coarse: its vertices and pad-frame positions, zero SED at rest,
// the path sampling (exact for a field linear in x, nothing off the sheet).

#include "scene/merkel_layer.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "scene/fingertip_scene.h"

namespace sedbridge::scene {
namespace {

class MerkelLayerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new FingertipScene(ParseSceneDescription(
        "model: B_coarse\nelasticity: linear\nbone: {}\nsurface_traction: true\n", "merkel.yaml"));
  }
  static void TearDownTestSuite() { delete scene_; }
  static MerkelLayer& layer() { return *scene_->merkel(); }
  static FingertipScene* scene_;
};
FingertipScene* MerkelLayerTest::scene_ = nullptr;

TEST_F(MerkelLayerTest, VerticesAreTheModelsMerkelNodesInThePadFrame) {
  const model::FingertipModel& m = scene_->model();
  ASSERT_EQ(layer().nodes(), m.merkel_nodes);
  ASSERT_EQ(layer().rest_pad_mm().cols(), Eigen::Index(m.merkel_nodes.size()));
  for (size_t k = 0; k < m.merkel_nodes.size(); k += 17) {
    const Eigen::Vector3d expected = m.pad_frame.ToPad(m.soft.rest_positions_m.col(m.merkel_nodes[k])) * 1e3;
    EXPECT_LT((layer().rest_pad_mm().col(Eigen::Index(k)) - expected).norm(), 1e-9);
  }
  // A closed layer around the finger: part faces the pad, part faces away.
  const auto& facing = layer().facing_pad();
  const long up = std::count(facing.begin(), facing.end(), 1);
  EXPECT_GT(up, 0);
  EXPECT_LT(up, long(facing.size()));
}

TEST_F(MerkelLayerTest, NoSedAtRest) {
  const Eigen::Matrix3Xd& rest = scene_->model().soft.rest_positions_m;
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(rest.data(), rest.size());
  const Eigen::VectorXd& sed = layer().Evaluate(x);
  ASSERT_EQ(sed.size(), Eigen::Index(layer().nodes().size()));
  EXPECT_LT(sed.cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(&sed, &layer().sed_Pa());
}

TEST_F(MerkelLayerTest, PathOfAFieldLinearInXIsExact) {
  const Eigen::Matrix3Xd& p = layer().rest_pad_mm();
  Eigen::VectorXd sed(p.cols());
  for (Eigen::Index k = 0; k < p.cols(); ++k) sed[k] = 100 + 7 * p(0, k);  // Pa
  const std::vector<PathSample> path = layer().SamplePath(sed, 0.0, -3.0, 3.0, 0.5);
  ASSERT_EQ(path.size(), 13u);  // the pad centre line is on the sheet from -3 to 3 mm
  for (size_t i = 0; i < path.size(); ++i) {
    EXPECT_NEAR(path[i].x_mm, -3.0 + 0.5 * double(i), 1e-12);
    EXPECT_NEAR(path[i].sed_Pa, 100 + 7 * path[i].x_mm, 1e-9);
  }
}

TEST_F(MerkelLayerTest, PathOffTheSheetIsEmpty) {
  const Eigen::VectorXd sed = Eigen::VectorXd::Ones(Eigen::Index(layer().nodes().size()));
  EXPECT_TRUE(layer().SamplePath(sed, 0.0, 500.0, 510.0, 1.0).empty());
}

}  // namespace
}  // namespace sedbridge::scene

namespace sedbridge::scene {
namespace {

// One-sided Merkel values (outputs.merkel_side): under a shear of the whole body every
// element has the same strain, so each side's SED is its material's; the dermis side reads
// the dermis value exactly, the epidermis side the epidermis value, and the two-sided mean
// lies between them at every vertex.
TEST(MerkelSide, EachSideReadsItsOwnMaterialAndBothLiesBetween) {
  const model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  auto scene_with = [&](const std::string& side) {
    return std::make_unique<FingertipScene>(
        ParseSceneDescription("model: B_coarse\nelasticity: linear\nbone: {}\noutputs: {merkel_side: " + side + "}\n",
                              "side.yaml"),
        model);
  };
  const auto both = scene_with("both"), epidermis = scene_with("epidermis"), dermis = scene_with("dermis");
  Eigen::VectorXd x(3 * model.num_soft_nodes());
  for (int i = 0; i < model.num_soft_nodes(); ++i) {
    const Eigen::Vector3d p = model.soft.rest_positions_m.col(i);
    x.segment<3>(3 * i) = p + Eigen::Vector3d(0.01 * p.z(), 0, 0);  // simple shear, gamma = 0.01
  }
  const Eigen::VectorXd s_both = both->merkel()->Evaluate(x);
  const Eigen::VectorXd s_epi = epidermis->merkel()->Evaluate(x);
  const Eigen::VectorXd s_der = dermis->merkel()->Evaluate(x);
  auto mu_of = [&](const std::string& name) {
    for (const auto& m : model.soft.materials)
      if (m.name == name) return m.lame_mu_Pa();
    return 0.0;
  };
  // Simple shear gamma: eps_xz = gamma / 2, SED = mu gamma^2 / 2 (linear elasticity).
  const double sed_epi = mu_of("epidermis") * 0.01 * 0.01 / 2, sed_der = mu_of("dermis") * 0.01 * 0.01 / 2;
  ASSERT_GT(sed_epi, 0.0);
  ASSERT_GT(std::abs(sed_epi - sed_der), 0.1 * sed_der);  // the layers differ in stiffness
  int mixed = 0;
  for (Eigen::Index v = 0; v < s_both.size(); ++v) {
    EXPECT_NEAR(s_epi[v], sed_epi, 1e-9 * sed_epi) << v;
    EXPECT_NEAR(s_der[v], sed_der, 1e-9 * sed_der) << v;
    EXPECT_GE(s_both[v], std::min(sed_epi, sed_der) * (1 - 1e-9));
    EXPECT_LE(s_both[v], std::max(sed_epi, sed_der) * (1 + 1e-9));
    mixed += std::abs(s_both[v] - sed_epi) > 1e-6 * sed_epi && std::abs(s_both[v] - sed_der) > 1e-6 * sed_der;
  }
  EXPECT_GT(mixed, 0);  // the two-sided mean mixes them
}

TEST(MerkelSide, AnUnknownSideIsAnErrorAtItsKey) {
  EXPECT_THROW(ParseSceneDescription("model: B_coarse\noutputs: {merkel_side: dermal}\n", "side.yaml"),
               std::exception);
}

}  // namespace
}  // namespace sedbridge::scene
