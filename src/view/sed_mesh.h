#pragma once
// The leader's fingertip for the 3-D panel, sent to the page once: the Merkel layer
// (epidermis-dermis interface, where the bridge reads SED) and the outer skin of a fingertip
// model, in the pad frame [mm] at rest. SED fields carry positions, not ids, so each field's
// vertices are matched to the mesh's by rest position (the bridge sends rest positions).
// The page colours the skin: each skin vertex takes the SED of the Merkel vertex beneath it
// (skin_merkel), so the frames carry the Merkel layer's field only.

#include <string>
#include <vector>

namespace sedbridge::view {

struct SedMesh {
  std::string model_id;
  std::vector<double> merkel_xyz_mm;  ///< 3 per Merkel-layer vertex
  std::vector<int> merkel_triangles;  ///< 3 vertex indices per triangle
  std::vector<double> skin_xyz_mm;    ///< 3 per skin vertex
  std::vector<int> skin_triangles;
  /// Per skin vertex, the Merkel vertex beneath it along the skin's inward normal; -1 where
  /// none is (the nail side, the finger's back: the layer lies under the pad only).
  std::vector<int> skin_merkel;
  std::string error;                  ///< why the mesh is empty (the page then draws points)

  std::size_t num_merkel_vertices() const { return merkel_xyz_mm.size() / 3; }
};

/// Loads `model` (a shipped name like "B" or a path; model::LoadFingertipModel). Never throws:
/// a model that does not load gives an empty mesh with `error` set.
SedMesh LoadSedMesh(const std::string& model);

/// skin_merkel of `mesh` from its two surfaces: for each skin vertex (normal: area-weighted over
/// its triangles, outward), the Merkel vertex closest to the line down that normal, if it lies
/// below the skin, within `max_depth_mm` of it, and within `max_off_axis_mm` of the line.
std::vector<int> MapSkinToMerkel(const SedMesh& mesh, double max_depth_mm = 3.0, double max_off_axis_mm = 1.5);

/// Maps a field's vertices (positions [mm], one per vertex) to mesh vertices by position
/// (within 1 um); -1 where no mesh vertex is there. Kept for the last field's size, since a
/// bridge sends the same vertices every step.
class SedVertexMatch {
 public:
  const std::vector<int>& Match(const SedMesh& mesh, const std::vector<float>& x_mm, const std::vector<float>& y_mm,
                                const std::vector<float>& z_mm);
  /// Vertices of the last field that matched a mesh vertex.
  std::size_t matched() const { return matched_; }

 private:
  std::vector<int> index_;
  std::vector<float> first_xyz_;  ///< the first vertex of the field matched, to notice a change
  std::size_t matched_ = 0;
};

}  // namespace sedbridge::view
