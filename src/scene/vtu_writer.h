#pragma once
// ParaView output: one VTK XML UnstructuredGrid (.vtu) per frame plus a .pvd collection
// that carries the "time" of each frame. Coordinates in mm (what users measure fingers in).
//
// Convention (ParaView's for warping): the points are the REFERENCE (undeformed) positions
// and the point array `displacement_mm` (the active vectors) holds deformed - reference.
// The file as loaded shows the undeformed finger; Filters > Warp By Vector (vectors
// displacement_mm, scale 1) shows the deformed one, exactly once.
// Cell array `tissue` holds an integer code per tet; FieldData arrays `tissue_<code>_<name>`
// (one value: the code) name them, e.g. tissue_0_epidermis.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "fem/tet_mesh.h"

namespace sedbridge::scene {

struct VtuField {
  std::string name;        ///< e.g. "sed_Pa", "traction_pad_Pa" (unit in the name)
  int components = 1;      ///< 1 or 3
  std::vector<double> values;  ///< components * count, point- or cell-major
};

/// Writes one .vtu of `mesh`: reference points [mm] plus `displacement_mm` = x - rest.
/// @param[in] path          output file
/// @param[in] mesh          soft mesh (rest positions [m], tets, tet_material, materials)
/// @param[in] x_m           deformed positions, 3 * #nodes [m]
/// @param[in] point_fields  extra per-node arrays (must not be named displacement_mm)
/// @param[in] cell_fields   extra per-tet arrays
/// @param[in] field_values  per-frame scalars written as FieldData, e.g. {"time_s", 0.5},
///                          {"step", 10}, {"plate_displacement_mm", 0.4}
/// Throws std::runtime_error when the file cannot be written.
void WriteVtu(const std::string& path, const fem::TetMesh& mesh, const Eigen::VectorXd& x_m,
              const std::vector<VtuField>& point_fields, const std::vector<VtuField>& cell_fields,
              const std::vector<std::pair<std::string, double>>& field_values = {});

/// Collects frames and writes the .pvd index (rewritten at each Add so an interrupted run
/// still opens). ParaView shows each frame's `timestep` as "Time"; what that time is — seconds
/// for dynamic and real-time runs, the load parameter for quasi-static ones — is named by
/// `time_meaning` in a comment at the top of the .pvd.
class PvdCollection {
 public:
  /// @param[in] pvd_path      the .pvd to write
  /// @param[in] time_meaning  e.g. "time since the first scan [s]" or
  ///                          "plate displacement [mm] (quasi-static load parameter)"
  explicit PvdCollection(std::string pvd_path, std::string time_meaning = "time [s]");
  /// Registers `vtu_file` (relative to the .pvd's folder) at `time` (in time_meaning's unit).
  void Add(double time, const std::string& vtu_file);

 private:
  std::string path_, time_meaning_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace sedbridge::scene
