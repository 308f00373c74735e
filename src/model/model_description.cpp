#include "model/model_description.h"

#include <filesystem>
#include <stdexcept>

#include "common/yaml_read_archive.h"
#include "model/fingertip_model.h"

namespace sedbridge::model {
namespace {

fem::LinearElasticMaterial Make(const std::string& name, double youngs_modulus_MPa,
                                double poisson_ratio, double density_g_cm3) {
  fem::LinearElasticMaterial m;
  m.name = name;
  m.youngs_modulus_Pa = youngs_modulus_MPa * 1e6;
  m.poisson_ratio = poisson_ratio;
  m.density_kg_m3 = density_g_cm3 * 1e3;
  return m;
}

// One tissue under `materials:`, in the units of the YAML.
struct MaterialKeys {
  double youngs_modulus_MPa = 0;
  double poisson_ratio = 0;
  double density_g_cm3 = 0;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("youngs_modulus_MPa", &youngs_modulus_MPa).Required().Positive());
    a->Visit(Field("poisson_ratio", &poisson_ratio).Required().Within({-1, 0.5, true, true}));
    a->Visit(Field("density_g_cm3", &density_g_cm3).Required().Positive());
  }
};

// `pad_frame:` of a model YAML.
struct PadFrameKeys {
  double tilt_deg = 0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(config::Field("tilt_deg", &tilt_deg).Required().Within({-90, 90, true, true}));
  }
};

const char* const kMaterialGroups[] = {kEpidermis, kDermis, kSubcutaneous, kSoftTissue,
                                       kStratumCorneum, kBone, kNail};

}  // namespace

fem::LinearElasticMaterial TableIIMaterial(const std::string& group) {
  if (group == kBone) return Make(group, 1.7e4, 0.30, 1.8);
  if (group == kSubcutaneous || group == kSoftTissue) return Make(group, 3.4e-2, 0.48, 1.0);
  if (group == kDermis) return Make(group, 8.0e-2, 0.48, 1.0);
  if (group == kEpidermis) return Make(group, 1.36e-1, 0.48, 1.0);
  if (group == kStratumCorneum) return Make(group, 1.993, 0.48, 1.1);
  if (group == kNail) return Make(group, 1.7e2, 0.30, 1.8);
  throw std::out_of_range("no Table II material for '" + group + "'");
}

ModelDescription ReadModelDescription(const std::string& yaml_path) {
  namespace fs = std::filesystem;
  const config::YamlDocument doc = config::LoadYamlFile(yaml_path);
  config::MapReader root(doc.root, doc.file);
  ModelDescription d;
  d.source_file = yaml_path;
  d.name = root.Required<std::string>("name");
  const std::string mesh = root.Required<std::string>("mesh");
  const fs::path mesh_path(mesh);
  d.mesh_path = mesh_path.is_absolute() ? mesh : (fs::path(yaml_path).parent_path() / mesh_path).string();
  const std::string unit = root.RequiredChoice("mesh_unit", {"mm", "m"});
  d.mesh_unit_m = unit == "mm" ? 1e-3 : 1.0;
  d.geometry = ReadFingertipGeometry(root, &d.has_geometry);

  d.materials_location = config::LocationOf(root.Node("materials"), doc.file);
  config::MapReader materials = root.Child("materials");
  for (const char* group : kMaterialGroups) {
    if (!materials.Has(group)) continue;
    config::MapReader m = materials.Child(group);
    MaterialKeys keys;
    config::ReadYaml(m, &keys);
    d.materials[group] = Make(group, keys.youngs_modulus_MPa, keys.poisson_ratio, keys.density_g_cm3);
  }
  materials.Finish();  // an unknown tissue name is an error, not silently ignored

  if (root.Has("pad_frame")) {
    config::MapReader pad = root.Child("pad_frame");
    PadFrameKeys keys;
    config::ReadYaml(pad, &keys);
    d.pad_tilt_deg = keys.tilt_deg;
  }
  root.Finish();
  // Rigid bodies and the shell only matter to reference solvers: Table II unless given.
  for (const char* group : {kStratumCorneum, kBone, kNail}) {
    if (!d.materials.count(group)) d.materials[group] = TableIIMaterial(group);
  }
  return d;
}

ModelDescription DefaultModelDescription(const std::string& msh_path) {
  ModelDescription d;
  d.name = std::filesystem::path(msh_path).stem().string();
  d.source_file = msh_path;
  d.mesh_path = msh_path;
  d.materials_location = {msh_path, 0, 0};
  for (const char* group : kMaterialGroups) d.materials[group] = TableIIMaterial(group);
  return d;
}

}  // namespace sedbridge::model
