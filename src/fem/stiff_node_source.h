#pragma once
// Which nodes carry stiffness far above the rest matrix's at this assembly (a penalty
// contact's springs). A warped-rest PCG adds their diagonal blocks to its preconditioner by a
// low-rank update (fem/stiff_node_update.h). The penalty contact term implements it.

#include <vector>

namespace sedbridge::fem {

class StiffNodeSource {
 public:
  virtual ~StiffNodeSource() = default;
  /// Appends the nodes (mesh node indices, duplicates allowed) whose diagonal blocks took
  /// extra stiffness at the last assembly.
  virtual void AppendStiffNodes(std::vector<int>& nodes) const = 0;
};

}  // namespace sedbridge::fem
