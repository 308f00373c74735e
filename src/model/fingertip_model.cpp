#include "model/fingertip_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <stdexcept>

#include "common/config_error.h"
#include "common/resource_path.h"

namespace sedbridge::model {
namespace {

using config::ConfigError;

// Plausible size of a fingertip model's soft tissue (bounding-box diagonal) [m].
constexpr double kMinModelExtent_m = 1e-3, kMaxModelExtent_m = 0.2;
// A tet whose signed volume is at most this times its longest edge cubed is inverted or
// degenerate [-]. A regular tet has 0.118: the bound is far below any usable element and far
// above round-off in the file's coordinates.
constexpr double kDegenerateTetVolumeRatio = 1e-10;

enum Tissue { kEpi, kDerm, kSub, kSoft, kBoneT, kNailT, kNumTissues };
const char* const kTissueNames[kNumTissues] = {kEpidermis, kDermis,  kSubcutaneous,
                                               kSoftTissue, kBone,   kNail};
bool IsSoft(int t) { return t <= kSoft; }

// A tetrahedron face: the three vertices opposite vertex i, ordered so that the normal of a
// positively oriented tet points out of it.
constexpr int kFaceVertices[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

using FaceKey = std::array<std::size_t, 3>;  // sorted vertex ids
FaceKey Key(std::size_t a, std::size_t b, std::size_t c) {
  FaceKey k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}
struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::size_t h = k[0];
    h = h * 1000003u ^ k[1];
    h = h * 1000003u ^ k[2];
    return h;
  }
};

struct RawTet {
  const MshElement* element;
  int tissue;
  std::array<std::size_t, 4> nodes;  // Gmsh node tags, positively oriented after Orient()
};

std::string Where(const MshElement& e) {
  return "element " + std::to_string(e.tag);
}

[[noreturn]] void FailAt(const MshFile& msh, const MshElement& e, const std::string& message) {
  throw ConfigError({msh.file, e.line, 0}, message);
}

double SignedVolume(const MshFile& msh, const std::array<std::size_t, 4>& n, double* max_edge) {
  Eigen::Vector3d x[4];
  for (int i = 0; i < 4; ++i) x[i] = msh.node_positions.col(msh.node_index.at(n[i]));
  double e = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) e = std::max(e, (x[i] - x[j]).norm());
  *max_edge = e;
  return (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]) / 6.0;
}

// Sorts every volume element into its tissue; rejects what the model cannot use.
std::vector<RawTet> ClassifyTets(const MshFile& msh) {
  std::vector<RawTet> tets;
  for (const MshElement& e : msh.elements) {
    if (e.entity_dim != 3) continue;
    const std::vector<int>& phys = msh.PhysicalTagsOf(e);
    int tissue = -1;
    for (int p : phys) {
      const std::string name = msh.PhysicalName(3, p);
      int t = -1;
      for (int k = 0; k < kNumTissues; ++k) {
        if (name == kTissueNames[k]) t = k;
      }
      if (t < 0) {
        FailAt(msh, e, "volume group '" + (name.empty() ? "#" + std::to_string(p) : name) +
                           "' (" + Where(e) + ") is not a tissue; expected epidermis, dermis, "
                           "subcutaneous, soft_tissue, bone or nail");
      }
      if (tissue >= 0 && tissue != t) {
        FailAt(msh, e, Where(e) + " is in two tissue groups, '" + kTissueNames[tissue] +
                           "' and '" + kTissueNames[t] + "'");
      }
      tissue = t;
    }
    if (tissue < 0) FailAt(msh, e, Where(e) + " belongs to no tissue group");
    if (e.type != 4) {
      FailAt(msh, e, Where(e) + " in '" + kTissueNames[tissue] + "' has Gmsh type " +
                         std::to_string(e.type) + "; only 4-node tetrahedra (type 4) are supported");
    }
    tets.push_back({&e, tissue, {e.node_tags[0], e.node_tags[1], e.node_tags[2], e.node_tags[3]}});
  }
  return tets;
}

// Gmsh tets are positive in our convention. A file whose tets are all (mostly) negative
// uses the mirrored convention and is flipped as a whole; a tet that still is not positive
// is inverted or degenerate.
void Orient(const MshFile& msh, std::vector<RawTet>* tets) {
  std::vector<double> volume(tets->size()), edge(tets->size());
  int negative = 0;
  for (std::size_t i = 0; i < tets->size(); ++i) {
    volume[i] = SignedVolume(msh, (*tets)[i].nodes, &edge[i]);
    if (volume[i] < 0) ++negative;
  }
  const bool flip = 2 * negative > static_cast<int>(tets->size());
  for (std::size_t i = 0; i < tets->size(); ++i) {
    RawTet& t = (*tets)[i];
    if (flip) {
      std::swap(t.nodes[1], t.nodes[2]);
      volume[i] = -volume[i];
    }
    if (volume[i] <= kDegenerateTetVolumeRatio * edge[i] * edge[i] * edge[i]) {
      const std::string what = volume[i] < 0 ? "is inverted" : "has zero volume";
      FailAt(msh, *t.element,
             "tetrahedron " + std::to_string(t.element->tag) + " in '" + kTissueNames[t.tissue] +
                 "' " + what + " (signed volume " + std::to_string(volume[i]) + " in file units^3" +
                 (flip ? ", after flipping the file's mirrored orientation" : "") + ")");
    }
  }
}

int AddMaterial(FingertipModel* m, const ModelDescription& d, const std::string& tissue) {
  const auto it = d.materials.find(tissue);
  if (it == d.materials.end()) {
    throw ConfigError(d.materials_location,
                      "the mesh has a '" + tissue + "' group but 'materials' has no '" + tissue + "' entry");
  }
  fem::LinearElasticMaterial mat = it->second;
  mat.name = tissue;
  m->soft.materials.push_back(mat);
  return static_cast<int>(m->soft.materials.size()) - 1;
}

struct FaceUse {
  int tet;   // soft tet index
  int face;  // 0..3, opposite vertex
};


// Stratum corneum thickness [m] when the model YAML gives no geometry (a bare .msh with a
// shell group): 20 um, the thin end of fingertip stratum corneum and model A's value.
constexpr double kDefaultStratumCorneumThickness_m = 0.02e-3;

// Number of volume elements per tissue.
using TissueCounts = std::array<int, kNumTissues>;

// Rejects meshes without soft tissue, with half a Merkel layer or without a rigid body.
TissueCounts CountTissues(const std::vector<RawTet>& tets, const config::SourceLocation& file_loc) {
  TissueCounts count{};
  for (const RawTet& t : tets) ++count[t.tissue];
  if (count[kEpi] + count[kDerm] + count[kSub] + count[kSoft] == 0) {
    throw ConfigError(file_loc, "no soft tissue: the mesh needs volume groups epidermis + dermis "
                                "(+ subcutaneous) or soft_tissue");
  }
  if ((count[kEpi] > 0) != (count[kDerm] > 0)) {
    throw ConfigError(file_loc, std::string("layered model without a Merkel layer: group '") +
                                    (count[kEpi] ? kDermis : kEpidermis) +
                                    "' is missing (the Merkel layer is the epidermis-dermis interface)");
  }
  if (count[kBoneT] + count[kNailT] == 0) {
    throw ConfigError(file_loc, "no rigid body: the mesh needs a 'bone' and/or 'nail' volume group");
  }
  return count;
}

// Gmsh node tag -> model node index, for the soft mesh and the rigid body separately.
struct NodeNumbering {
  std::vector<std::size_t> soft_tags;  // ascending; index = soft node
  std::unordered_set<std::size_t> rigid_node_tags;
  std::unordered_map<std::size_t, int> soft_index, rigid_index;
};

// Numbers the nodes of each body in ascending Gmsh tag order and fills the node positions
// (in metres), the soft node tags and the attached (soft and rigid) nodes of `m`.
NodeNumbering NumberNodes(const MshFile& msh, const std::vector<RawTet>& tets, double mesh_unit_m,
                          FingertipModel* m) {
  NodeNumbering n;
  for (const RawTet& t : tets) {
    if (IsSoft(t.tissue)) {
      n.soft_tags.insert(n.soft_tags.end(), t.nodes.begin(), t.nodes.end());
    } else {
      n.rigid_node_tags.insert(t.nodes.begin(), t.nodes.end());
    }
  }
  std::sort(n.soft_tags.begin(), n.soft_tags.end());
  n.soft_tags.erase(std::unique(n.soft_tags.begin(), n.soft_tags.end()), n.soft_tags.end());
  m->soft.rest_positions_m.resize(3, n.soft_tags.size());
  for (std::size_t i = 0; i < n.soft_tags.size(); ++i) {
    n.soft_index[n.soft_tags[i]] = static_cast<int>(i);
    m->soft.rest_positions_m.col(i) = msh.node_positions.col(msh.node_index.at(n.soft_tags[i])) * mesh_unit_m;
  }
  m->soft_node_tags = n.soft_tags;

  std::vector<std::size_t> rigid_tags(n.rigid_node_tags.begin(), n.rigid_node_tags.end());
  std::sort(rigid_tags.begin(), rigid_tags.end());
  m->rigid_positions_m.resize(3, rigid_tags.size());
  for (std::size_t i = 0; i < rigid_tags.size(); ++i) {
    n.rigid_index[rigid_tags[i]] = static_cast<int>(i);
    m->rigid_positions_m.col(i) = msh.node_positions.col(msh.node_index.at(rigid_tags[i])) * mesh_unit_m;
  }
  for (std::size_t i = 0; i < n.soft_tags.size(); ++i) {
    if (n.rigid_node_tags.count(n.soft_tags[i])) m->attached_nodes.push_back(static_cast<int>(i));
  }
  return n;
}

// A fingertip spans millimetres to centimetres. A mm mesh read as `mesh_unit: m` (or the
// reverse) is 1000x off and used to run to nonsense without a word.
void CheckModelExtent(const Eigen::Matrix3Xd& soft_positions_m, const config::SourceLocation& file_loc) {
  if (soft_positions_m.cols() == 0) return;
  const double diagonal_m = (soft_positions_m.rowwise().maxCoeff() - soft_positions_m.rowwise().minCoeff()).norm();
  if (!(diagonal_m >= kMinModelExtent_m && diagonal_m <= kMaxModelExtent_m))
    throw ConfigError(file_loc, "the soft tissue spans " + std::to_string(diagonal_m) +
                                    " m (bounding-box diagonal), outside the 1..200 mm of a fingertip: is "
                                    "mesh_unit right for this mesh?");
}

// Soft material index per tissue (-1 where absent); the rigid tissues' materials go to
// m->rigid_materials (Table II when the description names none).
std::array<int, kNumTissues> AddMaterials(const TissueCounts& count, const ModelDescription& d, FingertipModel* m) {
  std::array<int, kNumTissues> material_of;
  material_of.fill(-1);
  for (int k = kEpi; k <= kSoft; ++k) {
    if (count[k] > 0) material_of[k] = AddMaterial(m, d, kTissueNames[k]);
  }
  for (int k : {kBoneT, kNailT}) {
    if (count[k] > 0) {
      fem::LinearElasticMaterial mat = d.materials.count(kTissueNames[k])
                                           ? d.materials.at(kTissueNames[k])
                                           : TableIIMaterial(kTissueNames[k]);
      mat.name = kTissueNames[k];
      m->rigid_materials.push_back(mat);
    }
  }
  return material_of;
}

// Faces of the rigid body, as keys of Gmsh node tags.
using RigidFaceSet = std::unordered_set<FaceKey, FaceKeyHash>;

// Adds every tet to the soft mesh or the rigid body; returns the rigid body's faces.
RigidFaceSet AddTets(const std::vector<RawTet>& tets, const NodeNumbering& nodes,
                     const std::array<int, kNumTissues>& material_of, FingertipModel* m) {
  RigidFaceSet rigid_faces;
  for (const RawTet& t : tets) {
    fem::Tet tet;
    if (IsSoft(t.tissue)) {
      for (int i = 0; i < 4; ++i) tet[i] = nodes.soft_index.at(t.nodes[i]);
      m->soft.tets.push_back(tet);
      m->soft.tet_material.push_back(material_of[t.tissue]);
      m->soft_tet_tags.push_back(t.element->tag);
    } else {
      for (int i = 0; i < 4; ++i) tet[i] = nodes.rigid_index.at(t.nodes[i]);
      m->rigid_tets.push_back(tet);
      m->rigid_tet_is_nail.push_back(t.tissue == kNailT ? 1 : 0);
      m->rigid_tet_tags.push_back(t.element->tag);
      for (const auto& f : kFaceVertices) {
        rigid_faces.insert(Key(t.nodes[f[0]], t.nodes[f[1]], t.nodes[f[2]]));
      }
    }
  }
  return rigid_faces;
}

// Oriented surfaces of the soft mesh, keyed by sorted soft node indices (ordered maps:
// deterministic output).
struct SoftSurfaces {
  std::map<FaceKey, fem::Triangle> skin;    // free boundary faces (not on the rigid body)
  std::map<FaceKey, fem::Triangle> merkel;  // epidermis-dermis faces, normal dermis -> epidermis
};

// The tets using each face of `soft` (keyed by sorted node indices).
using FaceUses = std::unordered_map<FaceKey, std::vector<FaceUse>, FaceKeyHash>;
FaceUses SoftFaceUses(const fem::TetMesh& soft) {
  FaceUses faces;
  faces.reserve(soft.tets.size() * 3);
  for (int t = 0; t < soft.num_tets(); ++t) {
    const fem::Tet& tet = soft.tets[t];
    for (int f = 0; f < 4; ++f) {
      const auto& v = kFaceVertices[f];
      faces[Key(tet[v[0]], tet[v[1]], tet[v[2]])].push_back({t, f});
    }
  }
  return faces;
}

// Sorts the faces of the soft mesh: boundary (one tet) or interior (two tets).
SoftSurfaces FindSurfaces(const FingertipModel& m, const std::vector<std::size_t>& soft_tags,
                          const RigidFaceSet& rigid_faces, const std::array<int, kNumTissues>& material_of,
                          const config::SourceLocation& file_loc) {
  const FaceUses faces = SoftFaceUses(m.soft);
  auto oriented = [&](const FaceUse& u) {
    const fem::Tet& tet = m.soft.tets[u.tet];
    const auto& v = kFaceVertices[u.face];
    return fem::Triangle{tet[v[0]], tet[v[1]], tet[v[2]]};
  };
  SoftSurfaces surfaces;
  const int epi_mat = material_of[kEpi], derm_mat = material_of[kDerm];
  for (const auto& [key, uses] : faces) {
    if (uses.size() > 2) {
      std::string list;
      for (const auto& u : uses) list += " " + std::to_string(m.soft_tet_tags[u.tet]);
      throw ConfigError(file_loc, "non-manifold mesh: a face is shared by " + std::to_string(uses.size()) +
                                      " tetrahedra (elements" + list + ")");
    }
    if (uses.size() == 1) {
      const FaceKey tag_key = Key(soft_tags[key[0]], soft_tags[key[1]], soft_tags[key[2]]);
      if (!rigid_faces.count(tag_key)) surfaces.skin[key] = oriented(uses[0]);
      continue;
    }
    const int a = m.soft.tet_material[uses[0].tet], b = m.soft.tet_material[uses[1].tet];
    if (epi_mat >= 0 && ((a == epi_mat && b == derm_mat) || (a == derm_mat && b == epi_mat))) {
      surfaces.merkel[key] = oriented(a == derm_mat ? uses[0] : uses[1]);  // normal dermis -> epidermis
    }
  }
  if (epi_mat >= 0 && surfaces.merkel.empty()) {
    throw ConfigError(file_loc, "groups 'epidermis' and 'dermis' share no faces: the Merkel "
                                "interface is broken (meshes must be conforming, e.g. Gmsh "
                                "boolean fragments)");
  }
  if (surfaces.skin.empty()) throw ConfigError(file_loc, "the soft tissue has no free surface (no skin)");
  return surfaces;
}

// Triangles of `tris` into `out` and their sorted unique nodes into `nodes`.
void CollectTriangles(const std::map<FaceKey, fem::Triangle>& tris, std::vector<fem::Triangle>* out,
                      std::vector<int>* nodes) {
  for (const auto& [key, tri] : tris) {
    out->push_back(tri);
    nodes->insert(nodes->end(), tri.begin(), tri.end());
  }
  std::sort(nodes->begin(), nodes->end());
  nodes->erase(std::unique(nodes->begin(), nodes->end()), nodes->end());
}

// The skin triangle under stratum corneum shell element `e`; throws if it is none.
fem::Triangle SkinTriangleUnder(const MshFile& msh, const MshElement& e, const NodeNumbering& nodes,
                                const std::map<FaceKey, fem::Triangle>& skin) {
  if (e.type != 2) {
    FailAt(msh, e, Where(e) + " in 'stratum_corneum' has Gmsh type " + std::to_string(e.type) +
                       "; only 3-node triangles (type 2) are supported");
  }
  FaceKey key;
  for (int i = 0; i < 3; ++i) {
    const auto it = nodes.soft_index.find(e.node_tags[i]);
    if (it == nodes.soft_index.end()) {
      FailAt(msh, e, "stratum_corneum " + Where(e) + " uses node " + std::to_string(e.node_tags[i]) +
                         ", which is not a soft-tissue node");
    }
    key[i] = it->second;
  }
  std::sort(key.begin(), key.end());
  const auto s = skin.find(key);
  if (s == skin.end()) FailAt(msh, e, "stratum_corneum " + Where(e) + " is not a face of the skin surface");
  return s->second;
}

// Stratum corneum shell (model A): triangles of the 2-D group, oriented like the skin under
// them, with its material and thickness. Nothing when the mesh has no such group.
void AddStratumCorneum(const MshFile& msh, const ModelDescription& d, const NodeNumbering& nodes,
                       const std::map<FaceKey, fem::Triangle>& skin, const config::SourceLocation& file_loc,
                       FingertipModel* m) {
  int sc_group = -1;
  for (const auto& p : msh.physical_names) {
    if (p.dim == 2 && p.name == kStratumCorneum) sc_group = p.tag;
  }
  if (sc_group < 0) return;
  for (const MshElement& e : msh.elements) {
    if (e.entity_dim != 2) continue;
    const auto& phys = msh.PhysicalTagsOf(e);
    if (std::find(phys.begin(), phys.end(), sc_group) == phys.end()) continue;
    m->stratum_corneum_triangles.push_back(SkinTriangleUnder(msh, e, nodes, skin));
  }
  if (m->stratum_corneum_triangles.empty()) {
    throw ConfigError(file_loc, "group 'stratum_corneum' has no triangles");
  }
  m->stratum_corneum_material =
      d.materials.count(kStratumCorneum) ? d.materials.at(kStratumCorneum) : TableIIMaterial(kStratumCorneum);
  m->stratum_corneum_material.name = kStratumCorneum;
  m->stratum_corneum_thickness_m =
      d.has_geometry ? d.geometry.layers.stratum_corneum_mm * 1e-3 : kDefaultStratumCorneumThickness_m;
}

}  // namespace

int FingertipModel::MaterialIndex(const std::string& tissue) const {
  for (std::size_t i = 0; i < soft.materials.size(); ++i) {
    if (soft.materials[i].name == tissue) return static_cast<int>(i);
  }
  return -1;
}

PadFrame ComputePadFrame(const Eigen::Matrix3Xd& positions_m, const std::vector<int>& skin_nodes,
                         double tilt_deg) {
  PadFrame f;
  f.tilt_deg = tilt_deg;
  constexpr double kPi = 3.14159265358979323846;
  const double t = tilt_deg * kPi / 180.0;
  const Eigen::Vector3d x_pad(1, 0, 0), y_pad(0, std::cos(t), -std::sin(t)),
      z_pad(0, std::sin(t), std::cos(t));
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double best = -std::numeric_limits<double>::infinity();
  for (int n : skin_nodes) {
    const double h = z_pad.dot(positions_m.col(n));
    if (h > best) {
      best = h;
      origin = positions_m.col(n);
    }
  }
  Eigen::Matrix3d r;
  r << x_pad, y_pad, z_pad;
  f.model_from_pad = Eigen::Isometry3d::Identity();
  f.model_from_pad.linear() = r;
  f.model_from_pad.translation() = origin;
  return f;
}

FingertipModel BuildFingertipModel(const MshFile& msh, const ModelDescription& d) {
  FingertipModel m;
  m.name = d.name;
  m.source_file = d.source_file;
  m.description = d;
  const config::SourceLocation file_loc{msh.file, 0, 0};

  std::vector<RawTet> tets = ClassifyTets(msh);
  Orient(msh, &tets);
  const TissueCounts count = CountTissues(tets, file_loc);
  const NodeNumbering nodes = NumberNodes(msh, tets, d.mesh_unit_m, &m);
  CheckModelExtent(m.soft.rest_positions_m, file_loc);
  const std::array<int, kNumTissues> material_of = AddMaterials(count, d, &m);
  const RigidFaceSet rigid_faces = AddTets(tets, nodes, material_of, &m);
  const SoftSurfaces surfaces = FindSurfaces(m, nodes.soft_tags, rigid_faces, material_of, file_loc);
  CollectTriangles(surfaces.skin, &m.skin_triangles, &m.skin_nodes);
  CollectTriangles(surfaces.merkel, &m.merkel_triangles, &m.merkel_nodes);
  AddStratumCorneum(msh, d, nodes, surfaces.skin, file_loc, &m);
  m.pad_frame = ComputePadFrame(m.soft.rest_positions_m, m.skin_nodes, d.pad_tilt_deg);
  return m;
}

FingertipModel LoadFingertipModel(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  const std::string path = config::ResolveNameOrPath(name_or_path, "config/models");
  const std::string ext = fs::path(path).extension().string();
  ModelDescription d;
  if (ext == ".yaml" || ext == ".yml") {
    d = ReadModelDescription(path);
  } else if (ext == ".msh") {
    d = DefaultModelDescription(path);
  } else {
    throw ConfigError({name_or_path, 0, 0}, "expected a model name (A, B, ...), a model YAML "
                                            "or a Gmsh .msh file");
  }
  if (!fs::exists(d.mesh_path)) {
    throw ConfigError({d.source_file, 0, 0}, "mesh file '" + d.mesh_path + "' does not exist");
  }
  const MshFile msh = ReadMshFile(d.mesh_path);
  if (d.has_geometry && d.geometry.layers.stratum_corneum_mm > 0.0) {
    bool has_sc = false;
    for (const auto& pn : msh.physical_names) has_sc |= (pn.dim == 2 && pn.name == kStratumCorneum);
    if (!has_sc) {
      throw ConfigError({d.source_file, 0, 0}, "layers.stratum_corneum_mm > 0 but '" + d.mesh_path +
                                                   "' has no 'stratum_corneum' surface group");
    }
  }
  return BuildFingertipModel(msh, d);
}

std::size_t KeepMerkelVertices(FingertipModel* model, const MerkelVertexFilter& filter) {
  if (!filter) return model->merkel_nodes.size();
  const auto& keep = filter.keep;
  std::vector<char> kept(size_t(model->num_soft_nodes()), 0);
  std::vector<int> nodes;
  for (int v : model->merkel_nodes) {
    if (!keep(model->pad_frame.ToPad(model->soft.rest_positions_m.col(v)) * 1e3)) continue;
    kept[size_t(v)] = 1;
    nodes.push_back(v);
  }
  if (nodes.empty())
    throw std::invalid_argument("model '" + model->name + "': none of its " + std::to_string(model->merkel_nodes.size()) +
                                " Merkel-layer vertices lies where the SED is read" +
                                (filter.what.empty() ? std::string() : " (" + filter.what + ")"));
  std::vector<fem::Triangle> triangles;
  for (const fem::Triangle& t : model->merkel_triangles)
    if (kept[size_t(t[0])] && kept[size_t(t[1])] && kept[size_t(t[2])]) triangles.push_back(t);
  model->merkel_nodes = std::move(nodes);  // still sorted: a subsequence
  model->merkel_triangles = std::move(triangles);
  return model->merkel_nodes.size();
}

}  // namespace sedbridge::model
