#pragma once
// Reader for Gmsh MSH 4.1 ASCII files (the format of config/models/*.msh and of meshes users
// export from their own CT segmentations). Reads physical names, entities (their physical
// groups), nodes and elements; other sections ($Periodic, $NodeData, ...) are skipped.
// Binary and partitioned files and MSH 2.x are rejected with a clear error.
//
// Every error is a config::ConfigError naming the file and the line at fault.

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sedbridge::model {

/// One `$PhysicalNames` entry.
struct MshPhysicalName {
  int dim = 0;
  int tag = 0;
  std::string name;
  int line = 0;  ///< 1-based line in the file
};

/// One element as stored in the file (Gmsh tags, not indices).
struct MshElement {
  std::size_t tag = 0;                 ///< Gmsh element tag
  int type = 0;                        ///< Gmsh element type (2 = 3-node triangle, 4 = 4-node tet)
  int entity_dim = 0;                  ///< dimension of the entity holding the element
  int entity_tag = 0;                  ///< entity holding the element
  std::vector<std::size_t> node_tags;  ///< Gmsh node tags, in Gmsh's order
  int line = 0;                        ///< 1-based line of the element in the file
};

struct MshFile {
  std::string file;  ///< path used in messages
  std::vector<MshPhysicalName> physical_names;
  /// Physical tags of each entity, keyed by (entity dim, entity tag).
  std::map<std::pair<int, int>, std::vector<int>> entity_physical_tags;
  /// Node tags and positions (file units), in file order.
  std::vector<std::size_t> node_tags;
  Eigen::Matrix3Xd node_positions;
  /// Node tag -> column of node_positions.
  std::unordered_map<std::size_t, int> node_index;
  /// Elements of dimension 2 and 3 (points and lines are skipped), in file order.
  std::vector<MshElement> elements;

  /// Physical group tags (of dimension `dim`) an element's entity belongs to.
  const std::vector<int>& PhysicalTagsOf(const MshElement& e) const;
  /// Name of physical group (dim, tag), or "" if it has none.
  std::string PhysicalName(int dim, int tag) const;
};

/// Number of nodes of a Gmsh element type, or -1 if the type is unknown.
int MshNodesPerElement(int type);

/// Reads an MSH 4.1 ASCII file. Checks that every node an element references is defined
/// and that node and element tags are unique. Throws config::ConfigError (file:line).
MshFile ReadMshFile(const std::string& path);

/// Same as ReadMshFile, from text; `file` is used in messages only.
MshFile ReadMshString(const std::string& text, const std::string& file);

}  // namespace sedbridge::model
