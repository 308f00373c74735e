// Loader tests on the hand-written 3-tet fixture: regions, rigid body, skin, Merkel layer,
// pad frame, orientation, and every degenerate-input error naming the element or group.
#include "model/fingertip_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/config_error.h"
#include "tests/model/model_test_util.h"

namespace sedbridge::model {
namespace {

using testing::ReplaceLine;
using testing::ThreeTets;

FingertipModel Build(const std::string& text) {
  return BuildFingertipModel(ReadMshString(text, "fixture.msh"), DefaultModelDescription("fixture.msh"));
}

// Expects Build to fail; checks the line (0 = no line) and a message fragment.
void ExpectModelError(const std::string& text, int line, const std::string& fragment) {
  try {
    Build(text);
    FAIL() << "accepted; expected an error containing '" << fragment << "'";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().file, "fixture.msh");
    EXPECT_EQ(e.where().line, line) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

Eigen::Vector3d Normal(const Eigen::Matrix3Xd& x, const fem::Triangle& t) {
  return (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
}

TEST(FingertipModel, FixtureRegionsRigidBodyAndSurfaces) {
  const FingertipModel m = LoadFingertipModel(testing::FixturePath("three_tets.msh"));
  EXPECT_EQ(m.name, "three_tets");
  // Soft nodes are Gmsh nodes 1,2,3,4,6 (5 is bone-only), in tag order, in metres.
  ASSERT_EQ(m.num_soft_nodes(), 5);
  EXPECT_EQ(m.soft_node_tags, (std::vector<std::size_t>{1, 2, 3, 4, 6}));
  EXPECT_TRUE(m.soft.rest_positions_m.col(4).isApprox(Eigen::Vector3d(0.5e-3, -1e-3, 0.5e-3)));
  ASSERT_EQ(m.soft.num_tets(), 2);
  EXPECT_EQ(m.soft_tet_tags, (std::vector<std::size_t>{10, 11}));
  ASSERT_EQ(m.soft.materials.size(), 2u);
  EXPECT_EQ(m.soft.materials[m.soft.tet_material[0]].name, "epidermis");
  EXPECT_EQ(m.soft.materials[m.soft.tet_material[1]].name, "dermis");
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex("epidermis")].youngs_modulus_Pa, 0.136e6);
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex("dermis")].density_kg_m3, 1000.0);
  EXPECT_EQ(m.MaterialIndex("subcutaneous"), -1);

  EXPECT_EQ(m.attached_nodes, (std::vector<int>{0, 1, 2}));
  ASSERT_EQ(m.rigid_tets.size(), 1u);
  EXPECT_EQ(m.rigid_positions_m.cols(), 4);
  EXPECT_EQ(m.rigid_tet_is_nail, (std::vector<int>{0}));
  ASSERT_EQ(m.rigid_materials.size(), 1u);
  EXPECT_EQ(m.rigid_materials[0].name, "bone");

  // Skin: the 5 free faces not on the bone, pointing away from their tet.
  ASSERT_EQ(m.skin_triangles.size(), 5u);
  EXPECT_EQ(m.skin_nodes, (std::vector<int>{0, 1, 2, 3, 4}));
  for (const auto& t : m.skin_triangles) {
    for (const auto& tet : m.soft.tets) {
      int shared = 0;
      for (int v : t) shared += std::count(tet.begin(), tet.end(), v);
      if (shared != 3) continue;
      int apex = -1;
      for (int v : tet) if (std::count(t.begin(), t.end(), v) == 0) apex = v;
      const Eigen::Vector3d c = (m.soft.rest_positions_m.col(t[0]) + m.soft.rest_positions_m.col(t[1]) +
                                 m.soft.rest_positions_m.col(t[2])) / 3;
      EXPECT_LT(Normal(m.soft.rest_positions_m, t).dot(m.soft.rest_positions_m.col(apex) - c), 0);
    }
  }
  // Merkel: the one epidermis-dermis face (nodes 1,2,4), normal toward the epidermis (-y).
  ASSERT_EQ(m.merkel_triangles.size(), 1u);
  EXPECT_EQ(m.merkel_nodes, (std::vector<int>{0, 1, 3}));
  EXPECT_LT(Normal(m.soft.rest_positions_m, m.merkel_triangles[0]).y(), 0);
  EXPECT_TRUE(m.stratum_corneum_triangles.empty());
}

TEST(FingertipModel, PadFrameFollowsTiltAndTouchesTheExtremeSkinNode) {
  const FingertipModel m = Build(ThreeTets());
  const double t = 15.0 * M_PI / 180.0;
  const Eigen::Matrix3d r = m.pad_frame.model_from_pad.linear();
  EXPECT_TRUE(r.col(2).isApprox(Eigen::Vector3d(0, std::sin(t), std::cos(t))));
  EXPECT_TRUE(r.col(1).isApprox(Eigen::Vector3d(0, std::cos(t), -std::sin(t))));
  EXPECT_TRUE(r.col(0).isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  // Node 4 (0.3, 0.3, 1) mm is where the tilted plane touches first.
  EXPECT_TRUE(m.pad_frame.model_from_pad.translation().isApprox(Eigen::Vector3d(0.3e-3, 0.3e-3, 1e-3)));
  EXPECT_TRUE(m.pad_frame.ToPad(m.pad_frame.model_from_pad.translation()).isZero(1e-15));
}

TEST(FingertipModel, MirroredFileIsFlippedAsAWhole) {
  std::string text = ThreeTets();
  text = ReplaceLine(text, 35, "10 2 1 4 6");
  text = ReplaceLine(text, 37, "11 2 1 3 4");
  text = ReplaceLine(text, 39, "12 3 1 2 5");
  const FingertipModel m = Build(text);
  for (const auto& tet : m.soft.tets) {
    const auto& x = m.soft.rest_positions_m;
    EXPECT_GT((x.col(tet[1]) - x.col(tet[0])).cross(x.col(tet[2]) - x.col(tet[0])).dot(x.col(tet[3]) - x.col(tet[0])), 0);
  }
  EXPECT_EQ(m.merkel_triangles.size(), 1u);
}

TEST(FingertipModel, InvertedTetNamesElementAndLine) {
  // Tet 12 with two nodes swapped: the other two stay positive, so this one is inverted.
  ExpectModelError(ReplaceLine(ThreeTets(), 39, "12 1 2 3 5"), 39, "tetrahedron 12 in 'bone' is inverted");
}

TEST(FingertipModel, ZeroVolumeTetNamesElementAndLine) {
  // Node 6 moved into the plane of nodes 1, 2, 4.
  ExpectModelError(ReplaceLine(ThreeTets(), 30, "0.6 0.6 2"), 35, "tetrahedron 10 in 'epidermis' has zero volume");
}

TEST(FingertipModel, MissingDermisIsNamed) {
  ExpectModelError(ReplaceLine(ThreeTets(), 7, "3 2 \"subcutaneous\""), 0, "group 'dermis' is missing");
}

TEST(FingertipModel, NoSoftTissue) {
  std::string text = ReplaceLine(ThreeTets(), 6, "3 1 \"nail\"");
  text = ReplaceLine(text, 7, "3 2 \"bone\"");
  ExpectModelError(text, 0, "no soft tissue");
}

TEST(FingertipModel, NoRigidGroup) {
  ExpectModelError(ReplaceLine(ThreeTets(), 8, "3 4 \"subcutaneous\""), 0, "no rigid body");
}

TEST(FingertipModel, UnknownVolumeGroupNamesGroupAndElement) {
  ExpectModelError(ReplaceLine(ThreeTets(), 8, "3 4 \"tendon\""), 39, "'tendon' (element 12) is not a tissue");
}

TEST(FingertipModel, TetInNoGroupIsNamed) {
  ExpectModelError(ReplaceLine(ThreeTets(), 14, "3 0 -1 -1 1 1 1 0 0"), 39, "element 12 belongs to no tissue group");
}

TEST(FingertipModel, NonTetVolumeElementIsNamed) {
  std::string text = ReplaceLine(ThreeTets(), 38, "3 3 7 1");  // a pyramid
  text = ReplaceLine(text, 39, "12 1 3 2 5 6");
  ExpectModelError(text, 39, "element 12 in 'bone' has Gmsh type 7");
}

TEST(FingertipModel, NonConformingMerkelInterfaceIsBroken) {
  // The epidermis tet uses copies of nodes 1 and 2: it touches the dermis without sharing
  // a face.
  // Edits go bottom-up so that the line numbers of the fixture stay valid.
  std::string text = ThreeTets();
  text = ReplaceLine(text, 35, "10 7 8 4 6");
  text = ReplaceLine(text, 30, "0.5 -1 0.5\n0 0 0\n1 0 0");
  text = ReplaceLine(text, 24, "6\n7\n8");
  text = ReplaceLine(text, 18, "3 1 0 8");
  text = ReplaceLine(text, 17, "1 8 1 8");
  ExpectModelError(text, 0, "Merkel interface is broken");
}

TEST(FingertipModel, StratumCorneumMustLieOnTheSkin) {
  // Adds a surface entity in group stratum_corneum holding triangle 13 (nodes 1, 2, 6: a
  // true skin face). Edits go bottom-up so the fixture's line numbers stay valid; two
  // lines are inserted above the elements, so triangle 13 ends up on line 43.
  std::string text = ThreeTets();
  text = ReplaceLine(text, 39, "12 1 3 2 5\n2 7 2 1\n13 1 2 6");
  text = ReplaceLine(text, 33, "4 4 10 13");
  text = ReplaceLine(text, 12, "7 0 -1 -1 1 1 1 1 6 0\n1 0 -1 -1 1 1 1 1 1 0");
  text = ReplaceLine(text, 11, "0 0 1 3");
  text = ReplaceLine(text, 8, "3 4 \"bone\"\n2 6 \"stratum_corneum\"");
  text = ReplaceLine(text, 5, "4");
  const FingertipModel ok = Build(text);
  ASSERT_EQ(ok.stratum_corneum_triangles.size(), 1u);
  EXPECT_DOUBLE_EQ(ok.stratum_corneum_material.youngs_modulus_Pa, 1.993e6);
  // Face 1,2,4 is the Merkel interface, not skin.
  ExpectModelError(ReplaceLine(text, 43, "13 1 2 4"), 43, "element 13 is not a face of the skin");
}

TEST(FingertipModel, HomogeneousSoftTissueMeshHasNoMerkelLayer) {
  std::string text = ReplaceLine(ThreeTets(), 7, "3 2 \"soft_tissue\"");
  text = ReplaceLine(text, 6, "3 1 \"soft_tissue\"");
  const FingertipModel m = Build(text);
  ASSERT_EQ(m.soft.materials.size(), 1u);
  EXPECT_EQ(m.soft.materials[0].name, "soft_tissue");
  EXPECT_DOUBLE_EQ(m.soft.materials[0].youngs_modulus_Pa, 3.4e4);  // subcutaneous, Table II
  EXPECT_EQ(m.soft.tet_material, (std::vector<int>{0, 0}));
  EXPECT_TRUE(m.merkel_triangles.empty());
  EXPECT_TRUE(m.merkel_nodes.empty());
  EXPECT_EQ(m.skin_triangles.size(), 5u);  // the shared face is interior, not skin
}

// KeepMerkelVertices keeps the vertices its filter accepts (by pad-frame rest position),
// still sorted, and the triangles among them; none kept is an error.
TEST(FingertipModel, KeepMerkelVerticesKeepsTheChosenAndTheirTriangles) {
  FingertipModel m = LoadFingertipModel("B_coarse");
  const std::vector<int> all = m.merkel_nodes;
  ASSERT_GT(all.size(), 50u);
  auto near_pad_centre = [](const Eigen::Vector3d& p_mm) { return std::hypot(p_mm.x(), p_mm.y()) < 4 && p_mm.z() > -6; };
  const size_t kept = KeepMerkelVertices(&m, {near_pad_centre, "near the pad centre"});
  EXPECT_EQ(kept, m.merkel_nodes.size());
  EXPECT_GT(kept, 3u);
  EXPECT_LT(kept, all.size() / 2);
  EXPECT_TRUE(std::is_sorted(m.merkel_nodes.begin(), m.merkel_nodes.end()));
  size_t expected = 0;
  for (int v : all) {
    const bool in = near_pad_centre(m.pad_frame.ToPad(m.soft.rest_positions_m.col(v)) * 1e3);
    expected += in;
    EXPECT_EQ(std::binary_search(m.merkel_nodes.begin(), m.merkel_nodes.end(), v), in) << v;
  }
  EXPECT_EQ(kept, expected);
  EXPECT_FALSE(m.merkel_triangles.empty());
  for (const auto& t : m.merkel_triangles)
    for (int v : t) EXPECT_TRUE(std::binary_search(m.merkel_nodes.begin(), m.merkel_nodes.end(), v));
  try {
    KeepMerkelVertices(&m, {[](const Eigen::Vector3d&) { return false; }, "nowhere"});
    ADD_FAILURE() << "no vertex kept, no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("(nowhere)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(KeepMerkelVertices(&m, {}), kept);  // an empty filter keeps them all
}

TEST(FingertipModel, UnknownFileKind) {
  EXPECT_THROW(LoadFingertipModel("model.txt"), config::ConfigError);
  EXPECT_THROW(LoadFingertipModel("no_such_model_name"), config::ConfigError);
}

}  // namespace
}  // namespace sedbridge::model
