#pragma once
// A fingertip FE model: layered soft tissue (FE mesh), a rigid bone+nail body, the skin
// surface, the Merkel layer (epidermis-dermis interface) and the pad frame (design.md).
// Loaded from a model YAML (config/models/B.yaml) that points at a Gmsh MSH 4.1 file, or
// from a bare .msh whose physical groups use the tissue names below.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "fem/tet_mesh.h"
#include "model/model_description.h"
#include "model/msh_reader.h"

namespace sedbridge::model {

/// Physical group names (volumes) recognised in .msh files.
inline constexpr const char* kEpidermis = "epidermis";
inline constexpr const char* kDermis = "dermis";
inline constexpr const char* kSubcutaneous = "subcutaneous";
inline constexpr const char* kSoftTissue = "soft_tissue";  ///< homogeneous models
inline constexpr const char* kBone = "bone";
inline constexpr const char* kNail = "nail";
/// Surface group (model A): stratum corneum shell on the outer skin; reference solver only.
inline constexpr const char* kStratumCorneum = "stratum_corneum";

/// Pad frame: x lateral, y along the finger axis toward the tip, z along the outward pad
/// normal (toward the pressing plane); origin on the skin where the tilted plane first
/// touches. See design.md.
struct PadFrame {
  Eigen::Isometry3d model_from_pad = Eigen::Isometry3d::Identity();
  double tilt_deg = 15.0;  ///< angle between finger axis and the pressing plane

  Eigen::Vector3d ToPad(const Eigen::Vector3d& p_model) const { return model_from_pad.inverse() * p_model; }
};

struct FingertipModel {
  std::string name;         ///< "A", "B", "C", "B_fine", ... or the file stem
  std::string source_file;  ///< YAML or .msh it came from

  /// Soft tissue only (bone and nail are rigid). Nodes are renumbered 0..n-1 over the
  /// nodes used by soft tets; materials are one per tissue present, named after it.
  fem::TetMesh soft;

  /// Soft nodes shared with the bone or nail: they get the penalty bone coupling.
  std::vector<int> attached_nodes;

  /// Rigid body (bone + nail) for SDFs, export and viewing. Units m, model frame.
  Eigen::Matrix3Xd rigid_positions_m;
  std::vector<fem::Tet> rigid_tets;
  std::vector<int> rigid_tet_is_nail;  ///< 1 for nail tets, 0 for bone tets

  /// Outer skin: boundary faces of the soft mesh not touching the rigid body, oriented
  /// with outward normals. Indices are soft nodes.
  std::vector<fem::Triangle> skin_triangles;
  std::vector<int> skin_nodes;  ///< sorted unique

  /// Merkel layer: faces shared by an epidermis tet and a dermis tet, oriented outward
  /// (normal pointing from dermis to epidermis). Indices are soft nodes. Empty only for a
  /// homogeneous mesh (a single `soft_tissue` group); layered meshes always have one.
  std::vector<fem::Triangle> merkel_triangles;
  std::vector<int> merkel_nodes;  ///< sorted unique

  /// Model A only: stratum corneum shell triangles (soft node indices), else empty.
  std::vector<fem::Triangle> stratum_corneum_triangles;

  PadFrame pad_frame;

  // ---- Additions (beyond the first sketch of this header) ----

  /// Gmsh node tag of each soft node and Gmsh element tag of each soft tet, to relate
  /// results back to the .msh (export, error messages).
  std::vector<std::size_t> soft_node_tags;
  std::vector<std::size_t> soft_tet_tags;
  /// Gmsh element tag of each rigid tet.
  std::vector<std::size_t> rigid_tet_tags;
  /// Bone and nail materials (SI), for reference solvers that model them as elastic.
  std::vector<fem::LinearElasticMaterial> rigid_materials;
  /// Stratum corneum shell (model A): Table II material and thickness [m]; thickness 0
  /// when the model has no shell.
  fem::LinearElasticMaterial stratum_corneum_material;
  double stratum_corneum_thickness_m = 0.0;
  /// What the model YAML said (geometry parameters in mm, materials, ...); defaults for a
  /// bare .msh.
  ModelDescription description;

  int num_soft_nodes() const { return soft.num_nodes(); }
  /// Index of the soft material named `tissue`, or -1 if that tissue is not in the model.
  int MaterialIndex(const std::string& tissue) const;
};

/// Builds a model from an already read .msh and its description. Throws config::ConfigError
/// naming the element (Gmsh tag, file line) or group at fault.
FingertipModel BuildFingertipModel(const MshFile& msh, const ModelDescription& description);

/// Pad frame for tilt `tilt_deg`: z_pad = (0, sin t, cos t), y_pad = (0, cos t, -sin t),
/// x_pad = (1, 0, 0) in the model frame; origin = the skin node with the largest z_pad . p
/// (where the tilted plane first touches). `skin_nodes` index columns of `positions_m`.
PadFrame ComputePadFrame(const Eigen::Matrix3Xd& positions_m, const std::vector<int>& skin_nodes,
                         double tilt_deg);

/// Which Merkel-layer vertices a consumer reads, by rest position in the pad frame [mm]
/// (e.g. a display's sampling footprint: display::SedToCommandMapping::Reads).
struct MerkelVertexFilter {
  std::function<bool(const Eigen::Vector3d& rest_pad_mm)> keep;  ///< empty: every vertex
  std::string what;  ///< what it selects, for messages ("the sites of display 'suction_4x4' ...")
  explicit operator bool() const { return bool(keep); }
};

/// Keeps only the Merkel vertices `keep` accepts (and the Merkel triangles all of whose
/// vertices are kept), so that every SED evaluator built on the model afterwards works on
/// those alone. A kept vertex's SED is unchanged: it averages its own elements, whatever
/// else is in the layer. Returns the number kept; throws std::invalid_argument when none is
/// (naming the filter's `what`). An empty filter keeps every vertex.
std::size_t KeepMerkelVertices(FingertipModel* model, const MerkelVertexFilter& filter);

/// Loads a model from a model YAML or a .msh, or a shipped model by name ("B" means
/// config/models/B.yaml): config::ResolveNameOrPath.
/// Throws config::ConfigError naming the file and, for mesh defects, the element
/// (Gmsh element tag) or group at fault.
FingertipModel LoadFingertipModel(const std::string& name_or_path);

}  // namespace sedbridge::model
