#include "fem/tet_element.h"

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

TEST(TetElement, RestStiffnessIsSymmetricWithRigidNullSpace) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {1, 1, 1}, testing::Skin());
  for (const TetElement& e : PrecomputeElements(mesh)) {
    EXPECT_LT((RestStiffness(e) - RestStiffness(e).transpose()).norm(), 1e-9 * RestStiffness(e).norm());
    Eigen::Matrix<double, 12, 1> translation;
    for (int a = 0; a < 4; ++a) translation.segment<3>(3 * a) = Eigen::Vector3d(0.3, -0.2, 0.7);
    EXPECT_LT((RestStiffness(e) * translation).norm(), 1e-9 * RestStiffness(e).norm());
    EXPECT_GT(e.volume_m3, 0);
  }
}

TEST(TetElement, InvertedAndFlatTetsAreRejectedByIndex) {
  TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {1, 1, 1}, testing::Skin());
  std::swap(mesh.tets[3][1], mesh.tets[3][2]);
  try {
    PrecomputeElements(mesh);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("element 3 is inverted"), std::string::npos) << e.what();
  }
  TetMesh flat = MakeBoxMesh({0.01, 0.01, 0.01}, {1, 1, 1}, testing::Skin());
  flat.rest_positions_m.col(flat.tets[0][3]) = flat.rest_positions_m.col(flat.tets[0][2]);
  EXPECT_THROW(PrecomputeElements(flat), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::fem
