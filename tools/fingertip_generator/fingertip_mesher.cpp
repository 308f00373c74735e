#include "tools/fingertip_generator/fingertip_mesher.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

namespace sedbridge::tools {
namespace {

namespace occ = gmsh::model::occ;
using model::FingertipGeometry;

constexpr int kEpidermis = 0, kDermis = 1, kSubcutaneous = 2, kBone = 3, kNail = 4;
const char* const kGroupNames[5] = {"epidermis", "dermis", "subcutaneous", "bone", "nail"};

// Inner layers and the bone start this far below the crease plane so that the only face
// at y = 0 comes from the outer shape (no coincident planar faces in the fragment).
constexpr double kProximalOverhangMm = 1.0;

// The skin shape with every semi-axis reduced by `inset_mm`: a unit capsule (cylinder +
// sphere of radius 1 sharing the equator) scaled once by the semi-axes, so the cylinder and
// the ellipsoidal cap stay tangent-continuous.
int AddSkinShape(const model::OuterShapeParams& o, double inset_mm, double y_start_mm) {
  const double a = o.width_mm / 2 - inset_mm;           // x semi-axis
  const double b = o.depth_mm / 2 - inset_mm;           // z semi-axis
  const double c = o.tip_cap_length_mm - inset_mm;      // y semi-axis of the cap
  const double y_cap = o.length_mm - o.tip_cap_length_mm;  // cap centre
  const double y0 = y_start_mm / c, y1 = y_cap / c;     // in unit-capsule coordinates
  const int cylinder = occ::addCylinder(0, y0, 0, 0, y1 - y0, 0, 1.0);
  const int sphere = occ::addSphere(0, y1, 0, 1.0);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  occ::fuse({{3, cylinder}}, {{3, sphere}}, out, map);
  if (out.size() != 1) throw std::runtime_error("skin shape fuse gave " + std::to_string(out.size()) + " volumes");
  occ::dilate(out, 0, 0, 0, a, c, b);
  return out[0].second;
}

// Tapered elliptic shaft with an ellipsoidal tuft. The tuft radius is tuft_scale times the
// distal shaft radius so that the two surfaces cross instead of sharing an edge.
int AddBone(const model::BoneParams& p) {
  const double y0 = -kProximalOverhangMm;
  const double r0 = 1.0 + (1.0 - p.taper_ratio) * kProximalOverhangMm / p.length_mm;
  const int cone = occ::addCone(0, y0, 0, 0, p.length_mm - y0, 0, r0, p.taper_ratio);
  const int tuft = occ::addSphere(0, p.length_mm, 0, p.taper_ratio * p.tuft_scale);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  occ::fuse({{3, cone}}, {{3, tuft}}, out, map);
  if (out.size() != 1) throw std::runtime_error("bone fuse gave " + std::to_string(out.size()) + " volumes");
  // Scale the tuft's y extent like its section so the unit sphere becomes a rounded end.
  occ::dilate(out, 0, p.length_mm, 0, p.base_half_width_mm, 1.0, p.base_half_height_mm);
  occ::translate(out, 0, 0, p.center_z_mm);
  return out[0].second;
}

// Tool whose intersection with the outer shape is the nail plate: the dorsal box minus the
// skin shape shrunk by the nail thickness.
int AddNailTool(const FingertipGeometry& g) {
  const model::NailParams& n = g.nail;
  const double big = g.outer.depth_mm;  // reaches well beyond the dorsal skin
  const int box = occ::addBox(-n.half_width_mm, n.start_y_mm, -big, 2 * n.half_width_mm,
                              n.end_y_mm - n.start_y_mm, n.max_z_mm + big);
  const int inner = AddSkinShape(g.outer, n.thickness_mm, -kProximalOverhangMm);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  occ::cut({{3, box}}, {{3, inner}}, out, map);
  if (out.size() != 1) throw std::runtime_error("nail tool cut gave " + std::to_string(out.size()) + " volumes");
  return out[0].second;
}

void SetDeterministicOptions() {
  gmsh::option::setNumber("General.NumThreads", 1);
  gmsh::option::setNumber("Mesh.MaxNumThreads1D", 1);
  gmsh::option::setNumber("Mesh.MaxNumThreads2D", 1);
  gmsh::option::setNumber("Mesh.MaxNumThreads3D", 1);
  gmsh::option::setNumber("Geometry.OCCParallel", 0);
  gmsh::option::setNumber("Mesh.RandomSeed", 1);
  gmsh::option::setNumber("Mesh.Algorithm", 6);    // Frontal-Delaunay surfaces
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);  // Delaunay volumes
  gmsh::option::setNumber("Mesh.Optimize", 1);
  gmsh::option::setNumber("Mesh.OptimizeThreshold", 0.5);  // also improve fair tets (default 0.3)
  gmsh::option::setNumber("Mesh.OptimizeNetgen", 0);  // not compiled into Debian's Gmsh
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::option::setNumber("Mesh.Binary", 0);
  gmsh::option::setNumber("Mesh.SaveAll", 0);  // only elements in physical groups
}

bool IsCreaseFace(int surface_tag) {
  double x0, y0, z0, x1, y1, z1;
  gmsh::model::getBoundingBox(2, surface_tag, x0, y0, z0, x1, y1, z1);
  return std::abs(y1) < 1e-6 && std::abs(y0) < 1e-6;
}

}  // namespace

MeshStats MeshFingertip(const FingertipGeometry& g, const std::string& model_name,
                        const std::string& msh_path) {
  gmsh::clear();
  gmsh::model::add(model_name);
  SetDeterministicOptions();

  const double epi = g.layers.epidermis_mm, derm = g.layers.dermis_mm;
  const int outer = AddSkinShape(g.outer, 0.0, 0.0);
  const int epidermis_inner = AddSkinShape(g.outer, epi, -kProximalOverhangMm);
  const int dermis_inner = AddSkinShape(g.outer, epi + derm, -kProximalOverhangMm);
  const int bone = AddBone(g.bone);
  const int nail_tool = AddNailTool(g);

  // Inputs in this order; the fragment map tells which inputs contain each piece.
  const gmsh::vectorpair inputs = {{3, outer}, {3, epidermis_inner}, {3, dermis_inner},
                                   {3, bone}, {3, nail_tool}};
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  occ::fragment({inputs[0]}, {inputs.begin() + 1, inputs.end()}, out, map);

  std::set<int> in_input[5];
  for (int i = 0; i < 5; ++i) {
    for (const auto& dt : map[i]) {
      if (dt.first == 3) in_input[i].insert(dt.second);
    }
  }
  std::vector<int> group_volumes[5];
  gmsh::vectorpair outside;
  for (const auto& dt : out) {
    if (dt.first != 3) continue;
    const int v = dt.second;
    if (!in_input[0].count(v)) {
      outside.push_back(dt);  // nail tool beyond the skin, bone/layers below the crease
    } else if (in_input[3].count(v)) {
      group_volumes[kBone].push_back(v);
    } else if (in_input[4].count(v)) {
      group_volumes[kNail].push_back(v);
    } else if (in_input[2].count(v)) {
      group_volumes[kSubcutaneous].push_back(v);
    } else if (in_input[1].count(v)) {
      group_volumes[kDermis].push_back(v);
    } else {
      group_volumes[kEpidermis].push_back(v);
    }
  }
  occ::remove(outside, true);
  occ::synchronize();
  for (int k = 0; k < 5; ++k) {
    if (group_volumes[k].empty()) {
      throw std::runtime_error(std::string("the geometry has no ") + kGroupNames[k] + " volume");
    }
    gmsh::model::addPhysicalGroup(3, group_volumes[k], k + 1);
    gmsh::model::setPhysicalName(3, k + 1, kGroupNames[k]);
  }

  // Outer surfaces of the whole finger except the proximal cut at the crease.
  gmsh::vectorpair volumes, boundary;
  gmsh::model::getEntities(volumes, 3);
  gmsh::model::getBoundary(volumes, boundary, true, false, false);
  std::vector<int> skin_surfaces, stratum_corneum_surfaces;
  const std::set<int> epidermis_set(group_volumes[kEpidermis].begin(), group_volumes[kEpidermis].end());
  for (const auto& dt : boundary) {
    const int s = std::abs(dt.second);
    if (IsCreaseFace(s)) continue;
    skin_surfaces.push_back(s);
    std::vector<int> up, down;
    gmsh::model::getAdjacencies(2, s, up, down);
    if (up.size() == 1 && epidermis_set.count(up[0])) stratum_corneum_surfaces.push_back(s);
  }
  std::sort(skin_surfaces.begin(), skin_surfaces.end());
  std::sort(stratum_corneum_surfaces.begin(), stratum_corneum_surfaces.end());
  if (g.layers.stratum_corneum_mm > 0.0) {
    gmsh::model::addPhysicalGroup(2, stratum_corneum_surfaces, 6);
    gmsh::model::setPhysicalName(2, 6, "stratum_corneum");
  }

  // Size field: skin_mm down to the dermis-subcutaneous interface, then growing to core_mm.
  const int distance = gmsh::model::mesh::field::add("Distance");
  gmsh::model::mesh::field::setNumbers(distance, "FacesList",
                                       std::vector<double>(skin_surfaces.begin(), skin_surfaces.end()));
  gmsh::model::mesh::field::setNumber(distance, "NumPointsPerCurve", 100);
  // One such threshold per skin size (the pad refinement adds a finer one).
  auto skin_threshold = [&](double min_mm) {
    const int field = gmsh::model::mesh::field::add("Threshold");
    gmsh::model::mesh::field::setNumber(field, "InField", distance);
    gmsh::model::mesh::field::setNumber(field, "SizeMin", min_mm);
    gmsh::model::mesh::field::setNumber(field, "SizeMax", g.mesh_size.core_mm);
    gmsh::model::mesh::field::setNumber(field, "DistMin", epi + derm);
    gmsh::model::mesh::field::setNumber(field, "DistMax", epi + derm + g.mesh_size.transition_mm);
    return field;
  };
  const int threshold = skin_threshold(g.mesh_size.skin_mm);
  int background = threshold;
  const double pad_skin_mm = g.mesh_size.pad_skin_mm, pad_radius_mm = g.mesh_size.pad_radius_mm;
  if (pad_skin_mm > 0.0 && pad_radius_mm > 0.0) {
    // Inside the ball: the skin threshold with the finer size; outside it a huge size that
    // the Min below ignores. So only the skin near the pad is refined, not the deep core.
    const int fine = skin_threshold(pad_skin_mm);
    const int ball = gmsh::model::mesh::field::add("Ball");
    gmsh::model::mesh::field::setNumber(ball, "XCenter", g.mesh_size.pad_center_mm[0]);
    gmsh::model::mesh::field::setNumber(ball, "YCenter", g.mesh_size.pad_center_mm[1]);
    gmsh::model::mesh::field::setNumber(ball, "ZCenter", g.mesh_size.pad_center_mm[2]);
    gmsh::model::mesh::field::setNumber(ball, "Radius", pad_radius_mm);
    gmsh::model::mesh::field::setNumber(ball, "Thickness", g.mesh_size.transition_mm);
    gmsh::model::mesh::field::setNumber(ball, "VIn", pad_skin_mm);
    gmsh::model::mesh::field::setNumber(ball, "VOut", 1e3);
    const int inside = gmsh::model::mesh::field::add("Max");
    gmsh::model::mesh::field::setNumbers(inside, "FieldsList", {double(fine), double(ball)});
    background = gmsh::model::mesh::field::add("Min");
    gmsh::model::mesh::field::setNumbers(background, "FieldsList", {double(threshold), double(inside)});
  }
  gmsh::model::mesh::field::setAsBackgroundMesh(background);
  gmsh::option::setNumber("Mesh.MeshSizeMax", std::max(g.mesh_size.skin_mm, g.mesh_size.core_mm));

  gmsh::model::mesh::generate(3);
  gmsh::write(msh_path);

  MeshStats stats;
  std::set<std::size_t> soft_nodes;
  for (int k = 0; k < 5; ++k) {
    for (int v : group_volumes[k]) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> tags, nodes;
      gmsh::model::mesh::getElements(types, tags, nodes, 3, v);
      for (std::size_t t = 0; t < types.size(); ++t) {
        const int n = static_cast<int>(tags[t].size());
        stats.tets_per_group[k] += n;
        if (k <= kSubcutaneous) {
          stats.soft_tets += n;
          soft_nodes.insert(nodes[t].begin(), nodes[t].end());
        } else {
          stats.rigid_tets += n;
        }
      }
    }
  }
  stats.soft_nodes = static_cast<int>(soft_nodes.size());
  if (g.layers.stratum_corneum_mm <= 0.0) stratum_corneum_surfaces.clear();  // no group written
  for (int s : stratum_corneum_surfaces) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> tags, nodes;
    gmsh::model::mesh::getElements(types, tags, nodes, 2, s);
    for (const auto& t : tags) stats.stratum_corneum_triangles += static_cast<int>(t.size());
  }
  return stats;
}

}  // namespace sedbridge::tools
