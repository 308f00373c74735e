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
