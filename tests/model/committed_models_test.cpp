// The committed models in config/models/ load and look like a fingertip: sizes, layer
// depths, closed Merkel layer, pad frame, volumes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "model/fingertip_model.h"
#include "tests/model/mesh_geometry_util.h"

namespace sedbridge::model {
namespace {

using testing::BorderEdges;
using testing::DistanceToSurface;
using testing::TetVolume;

// Loaded once per model: loading A takes a moment.
const FingertipModel& Model(const std::string& name) {
  static std::map<std::string, FingertipModel> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, LoadFingertipModel(name)).first;
  return it->second;
}

double TissueVolume_mm3(const FingertipModel& m, const std::string& tissue) {
  const int mat = m.MaterialIndex(tissue);
  double v = 0;
  for (int t = 0; t < m.soft.num_tets(); ++t) {
    if (m.soft.tet_material[t] == mat) v += TetVolume(m.soft.rest_positions_m, m.soft.tets[t]);
  }
  return v * 1e9;
}

double RigidVolume_mm3(const FingertipModel& m) {
  double v = 0;
  for (const auto& t : m.rigid_tets) v += TetVolume(m.rigid_positions_m, t);
  return v * 1e9;
}

// Volume of the parametric skin shape (elliptic cylinder + half ellipsoid) inset by d mm.
double ShapeVolume_mm3(const FingertipModel& m, double inset_mm) {
  const auto& o = m.description.geometry.outer;
  const double a = o.width_mm / 2 - inset_mm, b = o.depth_mm / 2 - inset_mm,
               c = o.tip_cap_length_mm - inset_mm;
  return M_PI * a * b * (o.length_mm - o.tip_cap_length_mm) + 2.0 / 3.0 * M_PI * a * b * c;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

class CommittedModel : public ::testing::TestWithParam<std::string> {};

TEST_P(CommittedModel, LoadsWithPositiveTetsAndConsistentIndices) {
  const FingertipModel& m = Model(GetParam());
  EXPECT_EQ(m.name, GetParam());
  ASSERT_GT(m.soft.num_tets(), 0);
  EXPECT_EQ(m.soft.tet_material.size(), m.soft.tets.size());
  for (const auto& t : m.soft.tets) {
    for (int v : t) ASSERT_TRUE(v >= 0 && v < m.num_soft_nodes());
    ASSERT_GT(TetVolume(m.soft.rest_positions_m, t), 0);
  }
  for (const auto& t : m.rigid_tets) ASSERT_GT(TetVolume(m.rigid_positions_m, t), 0);
  EXPECT_EQ(m.rigid_tet_is_nail.size(), m.rigid_tets.size());
  EXPECT_GT(std::count(m.rigid_tet_is_nail.begin(), m.rigid_tet_is_nail.end(), 1), 0);
  EXPECT_GT(std::count(m.rigid_tet_is_nail.begin(), m.rigid_tet_is_nail.end(), 0), 0);
  EXPECT_GT(m.attached_nodes.size(), 50u);
  EXPECT_TRUE(std::is_sorted(m.skin_nodes.begin(), m.skin_nodes.end()));
  EXPECT_TRUE(std::is_sorted(m.merkel_nodes.begin(), m.merkel_nodes.end()));
  // Extent of the soft tissue: ~16 x 22 x 14 mm, crease at y = 0.
  const Eigen::Vector3d lo = m.soft.rest_positions_m.rowwise().minCoeff() * 1e3;
  const Eigen::Vector3d hi = m.soft.rest_positions_m.rowwise().maxCoeff() * 1e3;
  EXPECT_NEAR(hi.x() - lo.x(), 16.0, 0.3);
  EXPECT_NEAR(lo.y(), 0.0, 1e-9);
  EXPECT_NEAR(hi.y(), 22.0, 0.3);
  EXPECT_NEAR(hi.z() - lo.z(), 14.0, 0.3);
}

// Mean-ratio style quality 6 sqrt(2) V / l_rms^3: 1 for a regular tet, 0 for a flat one.
// Slivers make the FE step stiff and the corotational rotation ill-defined.
TEST_P(CommittedModel, NoSliversInTheSoftTissue) {
  const FingertipModel& m = Model(GetParam());
  const auto& x = m.soft.rest_positions_m;
  std::vector<double> quality;
  for (const auto& t : m.soft.tets) {
    double sum_sq = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) sum_sq += (x.col(t[i]) - x.col(t[j])).squaredNorm();
    const double l_rms = std::sqrt(sum_sq / 6);
    quality.push_back(6 * std::sqrt(2.0) * TetVolume(x, t) / (l_rms * l_rms * l_rms));
  }
  std::sort(quality.begin(), quality.end());
  EXPECT_GT(quality.front(), 0.01);
  EXPECT_GT(quality[quality.size() / 100], 0.25);  // 1st percentile
  EXPECT_GT(quality[quality.size() / 2], 0.6);
}

TEST_P(CommittedModel, VolumesMatchTheParametricShape) {
  const FingertipModel& m = Model(GetParam());
  const auto& layers = m.description.geometry.layers;
  const double soft = TissueVolume_mm3(m, kEpidermis) + TissueVolume_mm3(m, kDermis) +
                      TissueVolume_mm3(m, kSubcutaneous);
  const double total = soft + RigidVolume_mm3(m);
  // Straight-sided tets under-fill the curved skin a little.
  EXPECT_NEAR(total, ShapeVolume_mm3(m, 0), 0.04 * ShapeVolume_mm3(m, 0));
  EXPECT_GT(soft, 2500.0);
  // Epidermis + nail = outer shell of the epidermis thickness.
  const double shell = ShapeVolume_mm3(m, 0) - ShapeVolume_mm3(m, layers.epidermis_mm);
  double nail = 0;
  for (std::size_t t = 0; t < m.rigid_tets.size(); ++t) {
    if (m.rigid_tet_is_nail[t]) nail += TetVolume(m.rigid_positions_m, m.rigid_tets[t]) * 1e9;
  }
  EXPECT_NEAR(TissueVolume_mm3(m, kEpidermis) + nail, shell, 0.08 * shell);
}

TEST_P(CommittedModel, SkinIsOutwardAndBordersOnlyTheRigidBody) {
  const FingertipModel& m = Model(GetParam());
  const auto& x = m.soft.rest_positions_m;
  const auto& o = m.description.geometry.outer;
  const double y_cap = (o.length_mm - o.tip_cap_length_mm) * 1e-3;
  int inward = 0;
  for (const auto& t : m.skin_triangles) {
    const Eigen::Vector3d c = (x.col(t[0]) + x.col(t[1]) + x.col(t[2])) / 3;
    const Eigen::Vector3d n = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
    // Outward direction of the parametric shape (the crease face points to -y).
    Eigen::Vector3d out(c.x() / std::pow(o.width_mm / 2, 2), std::max(0.0, c.y() - y_cap) / std::pow(o.tip_cap_length_mm, 2),
                        c.z() / std::pow(o.depth_mm / 2, 2));
    if (c.y() < 1e-9) out = Eigen::Vector3d(0, -1, 0);
    if (n.dot(out) <= 0) ++inward;
  }
  EXPECT_EQ(inward, 0);
  bool consistent = false;
  const auto border = BorderEdges(m.skin_triangles, &consistent);
  EXPECT_TRUE(consistent);
  // The skin is closed except around the nail and the bone's cut at the crease.
  for (const auto& [a, b] : border) {
    ASSERT_TRUE(std::binary_search(m.attached_nodes.begin(), m.attached_nodes.end(), a));
    ASSERT_TRUE(std::binary_search(m.attached_nodes.begin(), m.attached_nodes.end(), b));
  }
}

TEST_P(CommittedModel, MerkelLayerIsClosedOutwardAndAtEpidermisDepth) {
  const FingertipModel& m = Model(GetParam());
  const auto& x = m.soft.rest_positions_m;
  ASSERT_GT(m.merkel_triangles.size(), 100u);
  bool consistent = false;
  const auto border = BorderEdges(m.merkel_triangles, &consistent);
  EXPECT_TRUE(consistent);
  EXPECT_FALSE(border.empty());
  for (const auto& [a, b] : border) {  // open only at the crease cut
    ASSERT_NEAR(x(1, a), 0.0, 1e-12);
    ASSERT_NEAR(x(1, b), 0.0, 1e-12);
  }
  // Enclosed volume by the divergence theorem with the field (0, y, 0): its flux through
  // the missing lid in the crease plane y = 0 is zero, so the open surface suffices.
  double volume = 0;
  for (const auto& t : m.merkel_triangles) {
    const Eigen::Vector3d n2 = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
    const double y = (x(1, t[0]) + x(1, t[1]) + x(1, t[2])) / 3;
    volume += y * n2.y() / 2;
  }
  const double epi = m.description.geometry.layers.epidermis_mm;
  EXPECT_NEAR(volume * 1e9, ShapeVolume_mm3(m, epi), 0.05 * ShapeVolume_mm3(m, epi));
  // Depth below the skin (away from the crease face): ~ the epidermis thickness.
  std::vector<fem::Triangle> skin;
  for (const auto& t : m.skin_triangles) {
    if (x(1, t[0]) + x(1, t[1]) + x(1, t[2]) > 1e-9) skin.push_back(t);
  }
  std::vector<double> depth_mm;
  for (int n : m.merkel_nodes) {
    if (x(1, n) > 3e-3) depth_mm.push_back(DistanceToSurface(x.col(n), x, skin) * 1e3);
  }
  ASSERT_GT(depth_mm.size(), 50u);
  EXPECT_NEAR(Median(depth_mm), epi, 0.15 * epi);
}

TEST_P(CommittedModel, PadFrameOriginIsTheSkinNodeTheTiltedPlaneTouchesFirst) {
  const FingertipModel& m = Model(GetParam());
  const auto& x = m.soft.rest_positions_m;
  const Eigen::Vector3d origin = m.pad_frame.model_from_pad.translation();
  const Eigen::Vector3d z_pad = m.pad_frame.model_from_pad.linear().col(2);
  bool on_skin = false;
  for (int n : m.skin_nodes) {
    on_skin |= (x.col(n) - origin).norm() < 1e-15;
    ASSERT_LE(z_pad.dot(x.col(n)), z_pad.dot(origin) + 1e-15);
  }
  EXPECT_TRUE(on_skin);
  // On the pad (palmar), toward the tip.
  EXPECT_GT(origin.z(), 3e-3);
  EXPECT_GT(origin.y(), 12e-3);
  EXPECT_NEAR(m.pad_frame.tilt_deg, 15.0, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Models, CommittedModel,
                         ::testing::Values("A", "B", "C", "B_coarse", "B_fine", "B_x4", "A_fine", "A_pad"));

TEST(ModelB, SizeMatchesThePaperWithin20Percent) {
  const FingertipModel& m = Model("B");
  EXPECT_NEAR(m.num_soft_nodes(), 1554, 0.2 * 1554);
  EXPECT_NEAR(m.soft.num_tets(), 7244, 0.2 * 7244);
  ASSERT_EQ(m.soft.materials.size(), 3u);
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex(kSubcutaneous)].youngs_modulus_Pa, 3.4e4);
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex(kDermis)].poisson_ratio, 0.48);
  // Layers: dermis (3 mm) > epidermis (1.5 mm) > the small subcutaneous core.
  EXPECT_GT(TissueVolume_mm3(m, kDermis), TissueVolume_mm3(m, kEpidermis));
  EXPECT_GT(TissueVolume_mm3(m, kEpidermis), TissueVolume_mm3(m, kSubcutaneous));
  EXPECT_TRUE(m.stratum_corneum_triangles.empty());
}

TEST(ModelA, LayersAndStratumCorneumShell) {
  const FingertipModel& m = Model("A");
  // Thin skin over a large core: subcutaneous > epidermis (1 mm) > dermis (0.75 mm).
  EXPECT_GT(TissueVolume_mm3(m, kSubcutaneous), TissueVolume_mm3(m, kEpidermis));
  EXPECT_GT(TissueVolume_mm3(m, kEpidermis), TissueVolume_mm3(m, kDermis));
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex(kEpidermis)].youngs_modulus_Pa, 1.36e5);
  // The shell covers the skin except the crease cut and the nail: each shell triangle is a
  // skin triangle with the same orientation.
  ASSERT_GT(m.stratum_corneum_triangles.size(), m.skin_triangles.size() / 2);
  EXPECT_LT(m.stratum_corneum_triangles.size(), m.skin_triangles.size());
  std::set<fem::Triangle> skin(m.skin_triangles.begin(), m.skin_triangles.end());
  for (const auto& t : m.stratum_corneum_triangles) ASSERT_TRUE(skin.count(t));
  EXPECT_NEAR(m.stratum_corneum_thickness_m, 0.02e-3, 1e-12);
  EXPECT_DOUBLE_EQ(m.stratum_corneum_material.youngs_modulus_Pa, 1.993e6);
}

TEST(ModelC, HomogeneousMaterialsOnModelAsGeometry) {
  const FingertipModel& a = Model("A");
  const FingertipModel& c = Model("C");
  for (const auto& mat : c.soft.materials) {
    EXPECT_DOUBLE_EQ(mat.youngs_modulus_Pa, 3.4e4) << mat.name;
    EXPECT_DOUBLE_EQ(mat.poisson_ratio, 0.48) << mat.name;
    EXPECT_DOUBLE_EQ(mat.density_kg_m3, 1000.0) << mat.name;
  }
  EXPECT_EQ(c.num_soft_nodes(), a.num_soft_nodes());
  EXPECT_EQ(c.soft.num_tets(), a.soft.num_tets());
  EXPECT_EQ(c.merkel_nodes, a.merkel_nodes);
  EXPECT_TRUE(c.stratum_corneum_triangles.empty());
}

TEST(ModelBVariants, ResolutionLadder) {
  const double b = Model("B").soft.num_tets();
  EXPECT_NEAR(Model("B_coarse").soft.num_tets() / b, 0.5, 0.15);
  EXPECT_NEAR(Model("B_fine").soft.num_tets() / b, 2.0, 0.4);
  EXPECT_NEAR(Model("B_x4").soft.num_tets() / b, 4.0, 0.8);
  // Same geometry and materials as B.
  for (const char* name : {"B_coarse", "B_fine", "B_x4"}) {
    const FingertipModel& v = Model(name);
    EXPECT_EQ(v.description.geometry.layers.epidermis_mm, 1.5) << name;
    EXPECT_EQ(v.description.geometry.layers.dermis_mm, 3.0) << name;
    EXPECT_DOUBLE_EQ(v.soft.materials[v.MaterialIndex(kDermis)].youngs_modulus_Pa, 8e4) << name;
  }
}

TEST(ModelAFine, FinerMeshOfTheSameModelA) {
  // The reference's own mesh-convergence pair (docs/validation.md): same layers, shell and
  // materials as A, more tets, a finer Merkel layer.
  const FingertipModel& a = Model("A");
  const FingertipModel& f = Model("A_fine");
  EXPECT_NEAR(f.soft.num_tets() / static_cast<double>(a.soft.num_tets()), 1.6, 0.3);
  EXPECT_GT(f.merkel_nodes.size(), a.merkel_nodes.size());
  EXPECT_EQ(f.description.geometry.layers.epidermis_mm, 1.0);
  EXPECT_EQ(f.description.geometry.layers.dermis_mm, 0.75);
  EXPECT_FALSE(f.stratum_corneum_triangles.empty());
  for (std::size_t i = 0; i < a.soft.materials.size(); ++i) {
    EXPECT_EQ(f.soft.materials[i].name, a.soft.materials[i].name);
    EXPECT_DOUBLE_EQ(f.soft.materials[i].youngs_modulus_Pa, a.soft.materials[i].youngs_modulus_Pa);
  }
  // Same outer shape: the plane first touches at the same height along the pad normal (the
  // touching node itself may sit elsewhere on the nearly flat pad).
  const Eigen::Vector3d z_pad = a.pad_frame.model_from_pad.linear().col(2);
  EXPECT_NEAR(z_pad.dot(f.pad_frame.model_from_pad.translation()), z_pad.dot(a.pad_frame.model_from_pad.translation()),
              0.05e-3);
}

TEST(ModelAPad, RefinedOnlyWhereThePadIsPressed) {
  // The C3D10 reference's pad-refined bracket (docs/validation.md): A with a finer skin
  // within pad_radius_mm of A's own pad frame origin.
  const FingertipModel& a = Model("A");
  const FingertipModel& p = Model("A_pad");
  const auto& size = p.description.geometry.mesh_size;
  const Eigen::Vector3d center_mm(size.pad_center_mm[0], size.pad_center_mm[1], size.pad_center_mm[2]);
  EXPECT_LT((a.pad_frame.model_from_pad.translation() * 1e3 - center_mm).norm(), 0.01);
  EXPECT_LT(size.pad_skin_mm, a.description.geometry.mesh_size.skin_mm);
  auto merkel_near = [&](const FingertipModel& m) {
    int n = 0;
    for (int v : m.merkel_nodes) n += (m.soft.rest_positions_m.col(v) * 1e3 - center_mm).norm() < 5.0;
    return n;
  };
  EXPECT_GT(merkel_near(p), 1.4 * merkel_near(a));
  EXPECT_LT(p.soft.num_tets(), 1.3 * a.soft.num_tets());
  for (std::size_t i = 0; i < a.soft.materials.size(); ++i) {
    EXPECT_DOUBLE_EQ(p.soft.materials[i].youngs_modulus_Pa, a.soft.materials[i].youngs_modulus_Pa);
  }
  EXPECT_FALSE(p.stratum_corneum_triangles.empty());
}

}  // namespace
}  // namespace sedbridge::model
