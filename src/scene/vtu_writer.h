#pragma once
// ParaView output: one VTK XML UnstructuredGrid (.vtu) per frame plus a .pvd collection
// that carries the time of each frame. Coordinates in mm (what users measure fingers in).

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "fem/tet_mesh.h"

namespace sedbridge::scene {

struct VtuField {
  std::string name;        ///< e.g. "sed_Pa", "displacement_mm"
  int components = 1;      ///< 1 or 3
  std::vector<double> values;  ///< components * count, point- or cell-major
};

/// Writes one .vtu of `mesh` deformed to positions x (3 * #nodes, metres).
void WriteVtu(const std::string& path, const fem::TetMesh& mesh, const Eigen::VectorXd& x_m,
              const std::vector<VtuField>& point_fields, const std::vector<VtuField>& cell_fields);

/// Collects frames and writes the .pvd index (rewritten at each Add so an interrupted run
/// still opens).
class PvdCollection {
 public:
  explicit PvdCollection(std::string pvd_path);
  /// Registers `vtu_file` (relative to the .pvd's folder) at time t.
  void Add(double t, const std::string& vtu_file);

 private:
  std::string path_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace sedbridge::scene
