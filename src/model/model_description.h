#pragma once
// What a model YAML (config/models/B.yaml) says about a fingertip model, apart from the mesh
// itself: where the .msh is, its unit, the materials per tissue group and the pad frame tilt.
// A bare .msh gets the defaults (mm, Table II materials, 15 degree tilt).

#include <map>
#include <string>

#include "common/config_error.h"
#include "fem/linear_elastic_material.h"
#include "model/fingertip_geometry.h"

namespace sedbridge::model {

struct ModelDescription {
  std::string name;         ///< model name ("B"), or the .msh file stem
  std::string source_file;  ///< the YAML (or .msh) it was read from
  std::string mesh_path;    ///< the .msh, resolved (relative paths are relative to the YAML)
  double mesh_unit_m = 1e-3;  ///< metres per .msh coordinate unit (mesh_unit: mm -> 1e-3)
  /// Material per physical group name (SI). Soft groups in the mesh must have an entry.
  std::map<std::string, fem::LinearElasticMaterial> materials;
  config::SourceLocation materials_location;  ///< where `materials` is, for messages
  double pad_tilt_deg = 15.0;
  /// Generator parameters (mm); `has_geometry` is false for a user's own mesh.
  FingertipGeometry geometry;
  bool has_geometry = false;
};

/// Paper Table II for a tissue group name (epidermis, dermis, subcutaneous, soft_tissue =
/// subcutaneous, stratum_corneum, bone, nail), in SI units. Throws std::out_of_range for
/// other names.
fem::LinearElasticMaterial TableIIMaterial(const std::string& group);

/// Reads a model YAML strictly (unknown keys are errors naming file:line:column):
///   name, mesh, mesh_unit (mm|m), geometry/layers/mesh_size (optional, see
///   fingertip_geometry.h), materials {group: {youngs_modulus_MPa, poisson_ratio,
///   density_g_cm3}}, pad_frame {tilt_deg}.
/// Throws config::ConfigError.
ModelDescription ReadModelDescription(const std::string& yaml_path);

/// Defaults for a bare .msh: name = file stem, mm, Table II materials, 15 degree tilt.
ModelDescription DefaultModelDescription(const std::string& msh_path);

}  // namespace sedbridge::model
