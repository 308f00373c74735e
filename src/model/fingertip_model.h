#pragma once
// A fingertip FE model: layered soft tissue (FE mesh), a rigid bone+nail body, the skin
// surface, the Merkel layer (epidermis-dermis interface) and the pad frame (design.md).
// Loaded from a model YAML (config/models/B.yaml) that points at a Gmsh MSH 4.1 file, or
// from a bare .msh whose physical groups use the tissue names below.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "fem/tet_mesh.h"

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
  Eigen::Vector3d ToModel(const Eigen::Vector3d& p_pad) const { return model_from_pad * p_pad; }
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
  /// (normal pointing from dermis to epidermis). Indices are soft nodes.
  std::vector<fem::Triangle> merkel_triangles;
  std::vector<int> merkel_nodes;  ///< sorted unique

  /// Model A only: stratum corneum shell triangles (soft node indices), else empty.
  std::vector<fem::Triangle> stratum_corneum_triangles;

  PadFrame pad_frame;

  int num_soft_nodes() const { return soft.num_nodes(); }
};

/// Loads a model from a model YAML or a .msh. Relative paths are resolved with
/// config::ResolveResource; a bare name "B" means config/models/B.yaml.
/// Throws config::ConfigError naming the file and, for mesh defects, the element
/// (Gmsh element tag) or group at fault.
FingertipModel LoadFingertipModel(const std::string& name_or_path);

}  // namespace sedbridge::model
