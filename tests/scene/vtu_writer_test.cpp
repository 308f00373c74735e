// ParaView output: reference points + displacement (Warp By Vector deforms exactly once),
// tissue names as FieldData, the PVD names what its time is.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "scene/vtu_writer.h"
#include "tests/common/child_process.h"

namespace sedbridge::scene {
namespace {

using sedbridge::testing::Slurp;

// The numbers of the first <DataArray> after `marker` (e.g. "<Points>").
std::vector<double> ArrayAfter(const std::string& xml, const std::string& marker) {
  const size_t at = xml.find(marker);
  if (at == std::string::npos) return {};
  // The array whose tag holds `marker`, else the first one after it.
  const size_t tag = xml.rfind("<DataArray", at) != std::string::npos &&
                             xml.find('>', xml.rfind("<DataArray", at)) > at
                         ? xml.rfind("<DataArray", at)
                         : xml.find("<DataArray", at);
  const size_t open = xml.find('>', tag) + 1;
  std::istringstream in(xml.substr(open, xml.find("</DataArray>", open) - open));
  std::vector<double> v;
  for (double d; in >> d;) v.push_back(d);
  return v;
}

fem::TetMesh OneTet() {
  fem::TetMesh m;
  m.rest_positions_m.resize(3, 4);
  m.rest_positions_m << 0, 1e-3, 0, 0,  //
      0, 0, 1e-3, 0,                    //
      0, 0, 0, 1e-3;
  m.tets = {{0, 1, 2, 3}};
  m.tet_material = {1};
  m.materials.resize(2);
  m.materials[0].name = "epidermis";
  m.materials[1].name = "dermis";
  return m;
}

TEST(VtuWriter, PointsAreTheReferenceAndDisplacementIsAddedOnce) {
  const fem::TetMesh mesh = OneTet();
  Eigen::VectorXd x(12);
  for (int i = 0; i < 4; ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  x[11] -= 0.2e-3;  // node 3 pressed down 0.2 mm
  const std::string path = ::testing::TempDir() + "/vtu_writer_" + std::to_string(::getpid()) + ".vtu";
  WriteVtu(path, mesh, x, {}, {}, {{"plate_displacement_mm", 0.25}});
  const std::string xml = Slurp(path);
  const std::vector<double> points = ArrayAfter(xml, "<Points>");
  const std::vector<double> disp = ArrayAfter(xml, "Name=\"displacement_mm\"");
  ASSERT_EQ(points.size(), 12u);
  ASSERT_EQ(disp.size(), 12u);
  for (int i = 0; i < 4; ++i)
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(points[size_t(3 * i + a)], mesh.rest_positions_m(a, i) * 1e3, 1e-9) << "reference, not deformed";
      // What Warp By Vector (scale 1) shows: reference + displacement = deformed, once.
      EXPECT_NEAR(points[size_t(3 * i + a)] + disp[size_t(3 * i + a)], x[3 * i + a] * 1e3, 1e-9);
    }
  EXPECT_NE(xml.find("<PointData Vectors=\"displacement_mm\">"), std::string::npos);
  EXPECT_NE(xml.find("Name=\"tissue_0_epidermis\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"tissue_1_dermis\""), std::string::npos);
  EXPECT_EQ(ArrayAfter(xml, "<CellData"), std::vector<double>{1.0});
  EXPECT_NE(xml.find("Name=\"plate_displacement_mm\" NumberOfTuples=\"1\" format=\"ascii\">0.25<"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(VtuWriter, PvdNamesWhatItsTimeIs) {
  const std::string path = ::testing::TempDir() + "/vtu_writer_" + std::to_string(::getpid()) + ".pvd";
  PvdCollection pvd(path, "plate displacement [mm] (quasi-static: a load parameter, not time)");
  pvd.Add(0.4, "frame_0010.vtu");
  const std::string xml = Slurp(path);
  EXPECT_NE(xml.find("<!-- sedbridge: timestep = plate displacement [mm]"), std::string::npos);
  EXPECT_NE(xml.find("timestep=\"0.4\" group=\"\" part=\"0\" file=\"frame_0010.vtu\""), std::string::npos);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sedbridge::scene
