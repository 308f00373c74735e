#include "model/fingertip_geometry.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sedbridge::model {
namespace {

using config::MapReader;

// Reads a required positive length (or other quantity) and checks a lower bound.
double Positive(MapReader& r, const std::string& key) {
  const double v = r.Required<double>(key);
  if (!(v > 0.0)) r.Fail(r.node()[key], "'" + key + "' must be > 0");
  return v;
}

double NonNegative(MapReader& r, const std::string& key) {
  const double v = r.Required<double>(key);
  if (!(v >= 0.0)) r.Fail(r.node()[key], "'" + key + "' must be >= 0");
  return v;
}

}  // namespace

FingertipGeometry ReadFingertipGeometry(MapReader& model_yaml, bool* complete) {
  FingertipGeometry g;
  int present = 0;
  if (model_yaml.Has("geometry")) {
    ++present;
    MapReader geo = model_yaml.Child("geometry");
    g.outer.width_mm = Positive(geo, "width_mm");
    g.outer.depth_mm = Positive(geo, "depth_mm");
    g.outer.length_mm = Positive(geo, "length_mm");
    g.outer.tip_cap_length_mm = Positive(geo, "tip_cap_length_mm");
    if (g.outer.tip_cap_length_mm >= g.outer.length_mm) {
      geo.Fail(geo.node()["tip_cap_length_mm"], "'tip_cap_length_mm' must be < 'length_mm'");
    }
    {
      MapReader bone = geo.Child("bone");
      g.bone.length_mm = Positive(bone, "length_mm");
      g.bone.base_half_width_mm = Positive(bone, "base_half_width_mm");
      g.bone.base_half_height_mm = Positive(bone, "base_half_height_mm");
      g.bone.taper_ratio = Positive(bone, "taper_ratio");
      if (g.bone.taper_ratio > 1.0) bone.Fail(bone.node()["taper_ratio"], "'taper_ratio' must be <= 1");
      g.bone.tuft_scale = Positive(bone, "tuft_scale");
      g.bone.center_z_mm = bone.Required<double>("center_z_mm");
      if (g.bone.length_mm >= g.outer.length_mm) {
        bone.Fail(bone.node()["length_mm"], "bone 'length_mm' must be < the finger length");
      }
      if (g.bone.base_half_width_mm >= g.outer.width_mm / 2 ||
          std::abs(g.bone.center_z_mm) + g.bone.base_half_height_mm >= g.outer.depth_mm / 2) {
        bone.Fail("the bone base does not fit inside the skin");
      }
      bone.Finish();
    }
    {
      MapReader nail = geo.Child("nail");
      g.nail.thickness_mm = Positive(nail, "thickness_mm");
      g.nail.start_y_mm = NonNegative(nail, "start_y_mm");
      g.nail.end_y_mm = Positive(nail, "end_y_mm");
      g.nail.half_width_mm = Positive(nail, "half_width_mm");
      g.nail.max_z_mm = nail.Required<double>("max_z_mm");
      if (g.nail.end_y_mm <= g.nail.start_y_mm) {
        nail.Fail(nail.node()["end_y_mm"], "'end_y_mm' must be > 'start_y_mm'");
      }
      if (g.nail.max_z_mm >= 0.0) nail.Fail(nail.node()["max_z_mm"], "the nail is dorsal: 'max_z_mm' must be < 0");
      nail.Finish();
    }
    geo.Finish();
  }
  if (model_yaml.Has("layers")) {
    ++present;
    MapReader layers = model_yaml.Child("layers");
    g.layers.stratum_corneum_mm = NonNegative(layers, "stratum_corneum_mm");
    g.layers.epidermis_mm = Positive(layers, "epidermis_mm");
    g.layers.dermis_mm = Positive(layers, "dermis_mm");
    const double skin_mm = g.layers.epidermis_mm + g.layers.dermis_mm;
    const double min_semi_axis_mm =
        std::min({g.outer.width_mm / 2, g.outer.depth_mm / 2, g.outer.tip_cap_length_mm});
    if (skin_mm >= min_semi_axis_mm) {
      layers.Fail("epidermis + dermis (" + std::to_string(skin_mm) +
                  " mm) leave no subcutaneous core inside the skin");
    }
    if (g.nail.thickness_mm >= g.layers.epidermis_mm) {
      layers.Fail(layers.node()["epidermis_mm"],
                  "the nail plate must be thinner than the epidermis it replaces");
    }
    layers.Finish();
  }
  if (model_yaml.Has("mesh_size")) {
    ++present;
    MapReader size = model_yaml.Child("mesh_size");
    g.mesh_size.skin_mm = Positive(size, "skin_mm");
    g.mesh_size.core_mm = Positive(size, "core_mm");
    g.mesh_size.transition_mm = NonNegative(size, "transition_mm");
    size.Finish();
  }
  if (complete) *complete = (present == 3);
  return g;
}

}  // namespace sedbridge::model
