#include "model/fingertip_geometry.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/yaml_read_archive.h"

namespace sedbridge::model {

using config::MapReader;

FingertipGeometry ReadFingertipGeometry(MapReader& model_yaml, bool* complete) {
  FingertipGeometry g;
  config::YamlReadArchive archive(&model_yaml);
  g.Serialize(&archive);
  // What one key cannot say alone: the parts must fit inside each other.
  const YAML::Node root = model_yaml.node();
  if (const YAML::Node geo = root["geometry"]) {
    if (g.outer.tip_cap_length_mm >= g.outer.length_mm)
      model_yaml.Fail(geo["tip_cap_length_mm"], "'tip_cap_length_mm' must be < 'length_mm'");
    const YAML::Node bone = geo["bone"];
    if (g.bone.length_mm >= g.outer.length_mm)
      model_yaml.Fail(bone["length_mm"], "bone 'length_mm' must be < the finger length");
    if (g.bone.base_half_width_mm >= g.outer.width_mm / 2 ||
        std::abs(g.bone.center_z_mm) + g.bone.base_half_height_mm >= g.outer.depth_mm / 2)
      model_yaml.Fail(bone, "the bone base does not fit inside the skin");
    const YAML::Node nail = geo["nail"];
    if (g.nail.end_y_mm <= g.nail.start_y_mm) model_yaml.Fail(nail["end_y_mm"], "'end_y_mm' must be > 'start_y_mm'");
  }
  if (const YAML::Node layers = root["layers"]) {
    const double skin_mm = g.layers.epidermis_mm + g.layers.dermis_mm;
    const double min_semi_axis_mm =
        std::min({g.outer.width_mm / 2, g.outer.depth_mm / 2, g.outer.tip_cap_length_mm});
    if (skin_mm >= min_semi_axis_mm) {
      model_yaml.Fail(layers, "epidermis + dermis (" + std::to_string(skin_mm) +
                                  " mm) leave no subcutaneous core inside the skin");
    }
    if (g.nail.thickness_mm >= g.layers.epidermis_mm)
      model_yaml.Fail(layers["epidermis_mm"], "the nail plate must be thinner than the epidermis it replaces");
  }
  if (complete) *complete = root["geometry"] && root["layers"] && root["mesh_size"];
  return g;
}

}  // namespace sedbridge::model
