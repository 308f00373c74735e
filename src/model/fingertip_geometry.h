#pragma once
// Parameters of the parametric fingertip (model YAML keys `geometry`, `layers`, `mesh_size`).
// All lengths in mm, model frame: x lateral, y along the finger axis from the DIP crease
// (y = 0) toward the tip, z toward the pad (palmar +z, nail/dorsal -z).
//
// The generator (tools/fingertip_generator) builds the mesh from these; the loader reads
// them too so that a typo in a model YAML is an error even when only loading.

#include <array>

#include "common/name_value.h"

namespace sedbridge::config {
class MapReader;
}

namespace sedbridge::model {

/// Outer skin: an elliptic cylinder along y (semi-axes width/2 in x, depth/2 in z) from
/// y = 0, capped by a half ellipsoid (semi-axes width/2, tip_cap_length, depth/2) whose
/// far end is the tip at y = length. Inner layer surfaces are the same shape with every
/// semi-axis reduced by the cumulative layer thickness, so layers follow the outer skin.
struct OuterShapeParams {
  double width_mm = 16.0;          ///< lateral (x) extent
  double depth_mm = 14.0;          ///< dorsal-palmar (z) extent
  double length_mm = 22.0;         ///< DIP crease (y = 0) to tip
  double tip_cap_length_mm = 8.0;  ///< y semi-axis of the tip cap; < length_mm

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("width_mm", &width_mm).Required().Positive());
    a->Visit(Field("depth_mm", &depth_mm).Required().Positive());
    a->Visit(Field("length_mm", &length_mm).Required().Positive());
    a->Visit(Field("tip_cap_length_mm", &tip_cap_length_mm).Required().Positive());
  }
};

/// Distal phalanx: a tapered elliptic cone along y from the crease to `length_mm`, ending
/// in an ellipsoidal tuft, its axis shifted toward the dorsal side.
struct BoneParams {
  double length_mm = 17.0;            ///< y where the tapered shaft ends
  double base_half_width_mm = 3.5;    ///< x semi-axis at y = 0
  double base_half_height_mm = 2.5;   ///< z semi-axis at y = 0
  double taper_ratio = 0.6;           ///< distal / proximal section size, (0, 1]
  double tuft_scale = 1.15;           ///< tuft radius / distal shaft radius (> 1: no shared edge)
  double center_z_mm = -1.5;          ///< z of the bone axis (negative: dorsal)

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("length_mm", &length_mm).Required().Positive());
    a->Visit(Field("base_half_width_mm", &base_half_width_mm).Required().Positive());
    a->Visit(Field("base_half_height_mm", &base_half_height_mm).Required().Positive());
    a->Visit(Field("taper_ratio", &taper_ratio).Required().Within({0, 1, true, false}));
    a->Visit(Field("tuft_scale", &tuft_scale).Required().Positive());
    a->Visit(Field("center_z_mm", &center_z_mm).Required());
  }
};

/// Nail plate: the outer `thickness_mm` of the skin shape inside the box
/// |x| < half_width_mm, start_y_mm < y < end_y_mm, z < max_z_mm (dorsal side).
struct NailParams {
  double thickness_mm = 0.5;
  double start_y_mm = 10.0;
  double end_y_mm = 19.5;
  double half_width_mm = 5.5;
  double max_z_mm = -3.0;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("thickness_mm", &thickness_mm).Required().Positive());
    a->Visit(Field("start_y_mm", &start_y_mm).Required().NonNegative());
    a->Visit(Field("end_y_mm", &end_y_mm).Required().Positive());
    a->Visit(Field("half_width_mm", &half_width_mm).Required().Positive());
    a->Visit(Field("max_z_mm", &max_z_mm).Required().Below(0));  // dorsal
  }
};

/// Soft-tissue layer thicknesses measured inward from the outer skin (Table I).
struct LayerParams {
  double stratum_corneum_mm = 0.0;  ///< > 0: a `stratum_corneum` shell group on the skin (model A)
  double epidermis_mm = 1.5;
  double dermis_mm = 3.0;           ///< the rest of the soft tissue is subcutaneous

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("stratum_corneum_mm", &stratum_corneum_mm).Required().NonNegative());
    a->Visit(Field("epidermis_mm", &epidermis_mm).Required().Positive());
    a->Visit(Field("dermis_mm", &dermis_mm).Required().Positive());
  }
};

/// Target tetrahedron edge lengths. Size is `skin_mm` within epidermis + dermis depth of the
/// outer skin and grows linearly to `core_mm` over `transition_mm` further in.
struct MeshSizeParams {
  double skin_mm = 1.5;
  double core_mm = 1.5;
  double transition_mm = 2.0;
  /// Optional local refinement where the pad is pressed (a mesh convergence study refines
  /// only where the Merkel SED is read): within `pad_radius_mm` of `pad_center_mm` (model
  /// frame) the skin size is `pad_skin_mm`, growing to core_mm as elsewhere. 0 = off.
  double pad_skin_mm = 0.0;
  double pad_radius_mm = 0.0;
  std::array<double, 3> pad_center_mm{0.0, 0.0, 0.0};

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("skin_mm", &skin_mm).Required().Positive());
    a->Visit(Field("core_mm", &core_mm).Required().Positive());
    a->Visit(Field("transition_mm", &transition_mm).Required().NonNegative());
    a->Visit(Field("pad_skin_mm", &pad_skin_mm).NonNegative());
    a->Visit(Field("pad_radius_mm", &pad_radius_mm).NonNegative());
    a->Visit(Field("pad_center_mm", &pad_center_mm));
  }
};

struct FingertipGeometry {
  OuterShapeParams outer;
  BoneParams bone;
  NailParams nail;
  LayerParams layers;
  MeshSizeParams mesh_size;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    // Each mapping is optional as a whole; a mapping given must give every key.
    a->Section("geometry", [&](auto* g) {
      outer.Serialize(g);
      g->Visit(Field("bone", &bone).Required());
      g->Visit(Field("nail", &nail).Required());
    });
    a->Visit(Field("layers", &layers));
    a->Visit(Field("mesh_size", &mesh_size));
  }
};

/// Reads the `geometry`, `layers` and `mesh_size` mappings of a model YAML. Each mapping is
/// optional as a whole (a YAML for a user's own CT mesh has none), but a mapping that is
/// present must give every key (a generated model is fully described by its YAML). Unknown
/// keys and inconsistent values (layers thicker than the finger, bone outside the skin,
/// ...) are ConfigErrors naming file:line:column. Marks the three keys used in
/// `model_yaml`; does not call model_yaml.Finish().
/// @param[out] complete  true when all three mappings are present (the generator needs it).
FingertipGeometry ReadFingertipGeometry(config::MapReader& model_yaml, bool* complete = nullptr);

}  // namespace sedbridge::model
