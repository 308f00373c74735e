// Model YAML reading: strict keys, materials, units, geometry checks, name resolution.
#include "model/model_description.h"

#include <gtest/gtest.h>
#include "tests/common/scratch_dir.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "model/fingertip_model.h"
#include "tests/model/model_test_util.h"

namespace sedbridge::model {
namespace {

namespace fs = std::filesystem;

// Writes `yaml` to a temp file whose mesh key points at the 3-tet fixture.
std::string WriteYaml(const std::string& name, const std::string& yaml) {
  // Per process: ctest -j runs the tests of this file in parallel processes.
  const fs::path path = fs::path(sedbridge::testing::ScratchDir()) / name;
  std::ofstream(path) << yaml;
  return path.string();
}

const std::string kMesh = "mesh: " + testing::FixturePath("three_tets.msh") + "\n";
const std::string kMaterials =
    "materials:\n"
    "  epidermis: {youngs_modulus_MPa: 0.2, poisson_ratio: 0.45, density_g_cm3: 1.1}\n"
    "  dermis: {youngs_modulus_MPa: 0.1, poisson_ratio: 0.45, density_g_cm3: 1.0}\n";

void ExpectYamlError(const std::string& yaml, int line, const std::string& fragment) {
  const std::string path = WriteYaml("bad_model.yaml", yaml);
  try {
    LoadFingertipModel(path);
    FAIL() << "accepted; expected an error containing '" << fragment << "'";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_EQ(e.where().line, line) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

// The 3-tet fixture with its coordinates in metres (x 1e-3: the same 2.3 mm model).
std::string FixtureInMetres() {
  const fs::path path = fs::path(sedbridge::testing::ScratchDir()) / "three_tets_m.msh";
  std::ifstream in(testing::FixturePath("three_tets.msh"));
  std::ofstream out(path);
  bool nodes = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "$Nodes") nodes = true;
    if (line == "$EndNodes") nodes = false;
    double x, y, z;
    char rest;
    std::istringstream s(line);
    if (nodes && (s >> x >> y >> z) && !(s >> rest)) {
      out << x * 1e-3 << " " << y * 1e-3 << " " << z * 1e-3 << "\n";
    } else {
      out << line << "\n";
    }
  }
  return path.string();
}

TEST(ModelDescription, WrongMeshUnitIsAnError) {
  // A hostile input: a mm mesh read as metres (1000x too large) ran and gave nonsense.
  try {
    LoadFingertipModel(WriteYaml("unit.yaml", "name: x\n" + kMesh + "mesh_unit: m\n" + kMaterials));
    FAIL() << "a 2.3 m fingertip was accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("is mesh_unit right"), std::string::npos) << e.what();
  }
}

TEST(ModelDescription, YamlGivesNameUnitMaterialsAndTilt) {
  const std::string path = WriteYaml("m.yaml", "name: fixture\nmesh: " + FixtureInMetres() + "\nmesh_unit: m\n" +
                                                   kMaterials + "pad_frame: {tilt_deg: 20}\n");
  const FingertipModel m = LoadFingertipModel(path);
  EXPECT_EQ(m.name, "fixture");
  EXPECT_EQ(m.source_file, path);
  // mesh_unit m: coordinates are taken as metres.
  EXPECT_TRUE(m.soft.rest_positions_m.col(4).isApprox(Eigen::Vector3d(0.5e-3, -1e-3, 0.5e-3)));
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex("epidermis")].youngs_modulus_Pa, 0.2e6);
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex("epidermis")].density_kg_m3, 1100.0);
  EXPECT_DOUBLE_EQ(m.soft.materials[m.MaterialIndex("dermis")].poisson_ratio, 0.45);
  EXPECT_DOUBLE_EQ(m.pad_frame.tilt_deg, 20.0);
  // Bone material not given: Table II.
  ASSERT_EQ(m.rigid_materials.size(), 1u);
  EXPECT_DOUBLE_EQ(m.rigid_materials[0].youngs_modulus_Pa, 1.7e10);
  EXPECT_FALSE(m.description.has_geometry);
}

TEST(ModelDescription, UnknownKeyIsNamedWithLineAndColumn) {
  ExpectYamlError("name: x\n" + kMesh + "mesh_unit: mm\n" + kMaterials + "tilt: 3\n", 7, "unknown key 'tilt'");
}

TEST(ModelDescription, UnknownTissueInMaterials) {
  ExpectYamlError("name: x\n" + kMesh + "mesh_unit: mm\n" + kMaterials +
                      "  tendon: {youngs_modulus_MPa: 1, poisson_ratio: 0.3, density_g_cm3: 1}\n",
                  7, "unknown key 'tendon'");
}

TEST(ModelDescription, SoftGroupWithoutMaterial) {
  ExpectYamlError("name: x\n" + kMesh + "mesh_unit: mm\nmaterials:\n"
                  "  dermis: {youngs_modulus_MPa: 0.1, poisson_ratio: 0.45, density_g_cm3: 1.0}\n",
                  5, "'materials' has no 'epidermis' entry");
}

TEST(ModelDescription, BadValuesAreLocated) {
  ExpectYamlError("name: x\n" + kMesh + "mesh_unit: cm\n" + kMaterials, 3, "one of: mm, m");
  ExpectYamlError("name: x\n" + kMesh + "mesh_unit: mm\nmaterials:\n"
                  "  epidermis: {youngs_modulus_MPa: 0.2, poisson_ratio: 0.5, density_g_cm3: 1.1}\n",
                  5, "'poisson_ratio' must be in (-1, 0.5)");
}

TEST(ModelDescription, GeometryMustBeCompleteAndConsistent) {
  // Take B's YAML and break one value at a time.
  const std::string b = testing::ReadText(config::ResolveResource("config/models/B.yaml"));
  ASSERT_NE(b.find("tip_cap_length_mm: 8.0"), std::string::npos);
  std::string bad = b;
  bad.replace(bad.find("tip_cap_length_mm: 8.0"), 22, "tip_cap_length_mm: 30.0");
  bad.replace(bad.find("mesh: B.msh"), 11, kMesh.substr(0, kMesh.size() - 1));
  ExpectYamlError(bad, 16, "'tip_cap_length_mm' must be < 'length_mm'");
  bad = b;
  bad.replace(bad.find("  epidermis_mm: 1.5\n"), 20, "");
  ExpectYamlError(bad, 32, "missing required key 'epidermis_mm'");
  bad = b;
  bad.replace(bad.find("dermis_mm: 3.0"), 14, "dermis_mm: 6.0");
  ExpectYamlError(bad, 32, "no subcutaneous core");
}

TEST(ModelDescription, MissingMeshFile) {
  ExpectYamlError("name: x\nmesh: nowhere.msh\nmesh_unit: mm\n" + kMaterials, 0, "does not exist");
}

TEST(ModelDescription, BareNameYamlAndMshGiveTheSameMesh) {
  const FingertipModel by_name = LoadFingertipModel("B");
  const FingertipModel by_yaml = LoadFingertipModel(config::ResolveResource("config/models/B.yaml"));
  const FingertipModel bare = LoadFingertipModel(config::ResolveResource("config/models/B.msh"));
  EXPECT_EQ(by_name.name, "B");
  EXPECT_EQ(bare.name, "B");
  EXPECT_TRUE(by_name.description.has_geometry);
  EXPECT_FALSE(bare.description.has_geometry);
  EXPECT_EQ(by_name.soft.tets, by_yaml.soft.tets);
  EXPECT_EQ(by_name.soft.tets, bare.soft.tets);
  EXPECT_EQ(by_name.merkel_triangles, bare.merkel_triangles);
  EXPECT_TRUE(by_name.soft.rest_positions_m.isApprox(bare.soft.rest_positions_m));
  // A bare .msh gets Table II.
  for (const auto& mat : bare.soft.materials) {
    EXPECT_DOUBLE_EQ(mat.youngs_modulus_Pa, TableIIMaterial(mat.name).youngs_modulus_Pa);
  }
  EXPECT_DOUBLE_EQ(TableIIMaterial("soft_tissue").youngs_modulus_Pa, 3.4e4);
  EXPECT_THROW(TableIIMaterial("tendon"), std::out_of_range);
}

}  // namespace
}  // namespace sedbridge::model
