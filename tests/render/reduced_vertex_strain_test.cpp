// The influence reduced per vertex (render/reduced_vertex_strain.h): exact when it keeps
// every direction, the preload's SED kept whatever it drops, and no more left out than asked.
#include "render/reduced_vertex_strain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "render_test_util.h"

namespace sedbridge::render {
namespace {

// Pins' shape: offsets, two knots, and two materials (the epidermis-dermis interface).
ElementStrainInfluence PinLikeInfluence() {
  ElementStrainInfluence in = testing::SyntheticInfluence(7, 45, 1e-3);
  in.command_offset = {0.0, 0.5, 1.0, 0.2, 0.0, 2.0, 0.7};
  in.knot_command = {2.0, 5.0};
  in.strain_at_knot = {2.0 * in.strain_per_command, 3.5 * in.strain_per_command};
  // The second knot's response turned a little, so that segments span new directions.
  for (Eigen::Index r = 0; r < in.strain_per_command.rows(); r += kStrainComponents)
    in.strain_at_knot[1].row(r + 3) += 0.2 * in.strain_per_command.row(r + 2);
  for (Eigen::Index e = 1; e < in.mu_Pa.size(); e += 2) in.mu_Pa[e] = 30e3, in.lambda_Pa[e] = 1.2e6;
  // Six elements a vertex (as on a tet mesh), each its own strain direction per actuator:
  // a vertex's commands span more directions than a few, so that leaving some out shows.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  for (Eigen::MatrixXd* m : {&in.strain_per_command, &in.strain_at_knot[0], &in.strain_at_knot[1]})
    for (Eigen::Index r = 0; r < m->rows(); ++r)
      for (Eigen::Index c = 0; c < m->cols(); ++c) (*m)(r, c) *= 1.0 + 0.5 * jitter(rng);
  in.vertex_start.clear(), in.vertex_element.clear(), in.vertex_weight.clear();
  for (int v = 0; v + 6 <= int(in.mu_Pa.size()); ++v) {
    in.vertex_start.push_back(int(in.vertex_element.size()));
    for (int e = v; e < v + 6; ++e) in.vertex_element.push_back(e), in.vertex_weight.push_back(1.0 / 6.0);
  }
  in.vertex_start.push_back(int(in.vertex_element.size()));
  return in;
}

double RelativeDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

TEST(ReducedVertexStrain, KeepingEveryDirectionGivesTheElementsSedAndJacobian) {
  const ElementStrainInfluence in = PinLikeInfluence();
  ReducedVertexStrainStats stats;
  const ElementStrainInfluence reduced = ReduceStrainPerVertex(in, 0.0, &stats);
  EXPECT_LE(stats.largest_dropped_share, 1e-12);  // rounding of the eigenvalues
  const DisplayInfluence elements(in, 0.0), per_vertex(reduced, 0.0);
  ASSERT_EQ(per_vertex.num_vertices(), elements.num_vertices());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> command(0.0, 8.0);
  Eigen::VectorXd u(7), sed, reduced_sed;
  Eigen::MatrixXd J, reduced_J;
  for (int trial = 0; trial < 20; ++trial) {
    for (int i = 0; i < 7; ++i) u[i] = command(rng);
    elements.SedAndJacobian(u, sed, J);
    per_vertex.SedAndJacobian(u, reduced_sed, reduced_J);
    EXPECT_LE(RelativeDifference(reduced_sed, sed), 1e-5) << trial;  // single-precision slopes
    EXPECT_LE(RelativeDifference(reduced_J, J), 1e-5) << trial;
  }
}

TEST(ReducedVertexStrain, KeepsThePreloadsSedAndLeavesOutNoMoreThanAsked) {
  const ElementStrainInfluence in = PinLikeInfluence();
  const DisplayInfluence elements(in, 0.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> command(0.0, 8.0);
  std::vector<Eigen::VectorXd> commands(20, Eigen::VectorXd(7));
  for (Eigen::VectorXd& u : commands)
    for (int i = 0; i < 7; ++i) u[i] = command(rng);
  std::vector<double> errors;
  for (double share : {1e-4, 1e-2, 0.3}) {
    ReducedVertexStrainStats stats;
    const DisplayInfluence per_vertex(ReduceStrainPerVertex(in, share, &stats), 0.0);
    EXPECT_LE(stats.largest_dropped_share, share);
    // The preload's direction is always kept: its SED at rest exactly (to rounding).
    EXPECT_LE(RelativeDifference(per_vertex.preload_sed_Pa(), elements.preload_sed_Pa()), 1e-12) << share;
    // What the commands add, off by no more than the dropped share allows, and more so the
    // more is left out.
    double error = 0;
    Eigen::VectorXd sed, reduced_sed;
    for (const Eigen::VectorXd& u : commands) {
      elements.Sed(u, sed);
      per_vertex.Sed(u, reduced_sed);
      error = std::max(error, RelativeDifference(reduced_sed - per_vertex.preload_sed_Pa(), sed - elements.preload_sed_Pa()));
    }
    EXPECT_LE(error, 2.0 * std::sqrt(share)) << share;
    errors.push_back(error);
  }
  EXPECT_GT(errors[1], errors[0]);
  EXPECT_GE(errors[2], errors[1]);
}

TEST(ReducedVertexStrain, RefusesAnInconsistentInfluenceOrShare) {
  ElementStrainInfluence in = PinLikeInfluence();
  EXPECT_THROW(ReduceStrainPerVertex(in, 1.0), std::invalid_argument);
  EXPECT_THROW(ReduceStrainPerVertex(in, -0.1), std::invalid_argument);
  in.vertex_element.back() = int(in.mu_Pa.size());  // names no element
  EXPECT_THROW(ReduceStrainPerVertex(in, 0.01), std::invalid_argument);
  in = PinLikeInfluence();
  in.strain_at_knot[0](3, 2) = std::nan("");
  EXPECT_THROW(ReduceStrainPerVertex(in, 0.01), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::render
