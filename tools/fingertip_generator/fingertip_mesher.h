#pragma once
// Builds a fingertip model's geometry with the Gmsh OpenCASCADE kernel and meshes it
// (linear tetrahedra, Gmsh MSH 4.1 ASCII). Used only by the generator; the runtime reads
// .msh files itself (src/model/msh_reader.h).

#include <string>

#include "model/fingertip_geometry.h"

namespace sedbridge::tools {

/// Counts of the generated mesh, for the generator's report and the resolution study.
struct MeshStats {
  int soft_nodes = 0;   ///< nodes used by epidermis/dermis/subcutaneous tets
  int soft_tets = 0;
  int rigid_tets = 0;   ///< bone + nail
  int tets_per_group[5] = {0, 0, 0, 0, 0};  ///< epidermis, dermis, subcutaneous, bone, nail
  int stratum_corneum_triangles = 0;
};

/// Builds the geometry described by `geometry` (mm), meshes it deterministically (one
/// thread, fixed seed) and writes `msh_path` (MSH 4.1 ASCII, only physical groups saved).
/// Volume physical groups: epidermis (1), dermis (2), subcutaneous (3), bone (4), nail (5);
/// surface group stratum_corneum (6) when geometry.layers.stratum_corneum_mm > 0.
/// Must be called between gmsh::initialize() and gmsh::finalize().
/// Throws std::runtime_error when the geometry cannot be built.
MeshStats MeshFingertip(const model::FingertipGeometry& geometry, const std::string& model_name,
                        const std::string& msh_path);

}  // namespace sedbridge::tools
