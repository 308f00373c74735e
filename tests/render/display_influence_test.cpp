#include "render/display_influence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "fem/tet_sed.h"
#include "render_test_util.h"

namespace sedbridge::render {
namespace {

// Element SED of eps0 + E u straight from the tensor formula (fem/tet_sed.h), averaged.
Eigen::VectorXd DirectSed(const ElementStrainInfluence& in, const Eigen::VectorXd& u) {
  const Eigen::Index elements = in.mu_Pa.size();
  Eigen::VectorXd element(elements);
  const Eigen::VectorXd eps = in.preload_strain + in.strain_per_command * u;
  for (Eigen::Index e = 0; e < elements; ++e) {
    const double* s = eps.data() + kStrainComponents * e;
    fem::SymmetricStrainSed<double>(s[0], s[1], s[2], s[3], s[4], s[5], in.mu_Pa[e], in.lambda_Pa[e], element[e]);
  }
  Eigen::VectorXd vertex = Eigen::VectorXd::Zero(Eigen::Index(in.vertex_start.size()) - 1);
  for (Eigen::Index v = 0; v < vertex.size(); ++v)
    for (int k = in.vertex_start[size_t(v)]; k < in.vertex_start[size_t(v) + 1]; ++k)
      vertex[v] += in.vertex_weight[size_t(k)] * element[in.vertex_element[size_t(k)]];
  return vertex;
}

TEST(DisplayInfluence, QuadraticFormIsTheElementSedOfTheSuperposedStrain) {
  const ElementStrainInfluence in = testing::SyntheticInfluence(6, 40, 2e-3);
  const DisplayInfluence influence(in);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::VectorXd u = (Eigen::VectorXd::Random(6).array() + 1.0).matrix() * 5.0;
    Eigen::VectorXd sed;
    influence.Sed(u, sed);
    const Eigen::VectorXd direct = DirectSed(in, u);
    // The slopes are stored in single precision (display_influence.h): float rounding.
    EXPECT_LE((sed - direct).norm(), 1e-6 * direct.norm()) << trial;
  }
  Eigen::VectorXd zero_sed;
  influence.Sed(Eigen::VectorXd::Zero(6), zero_sed);
  EXPECT_LE((zero_sed - influence.preload_sed_Pa()).norm(), 1e-12 * zero_sed.norm());
  EXPECT_GT(zero_sed.minCoeff(), 0.0);  // the preload strains every element
}

TEST(DisplayInfluence, JacobianMatchesFiniteDifferences) {
  const DisplayInfluence influence(testing::SyntheticInfluence(5, 30, 1e-3));
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(5, 1.0, 9.0);
  Eigen::VectorXd sed, plus, minus;
  Eigen::MatrixXd J;
  influence.SedAndJacobian(u, sed, J);
  // The SED is quadratic in u: central differences are exact for any step, and a large one
  // keeps the single-precision slopes' rounding out of the difference quotient.
  const double h = 0.5;
  for (int a = 0; a < 5; ++a) {
    Eigen::VectorXd up = u, um = u;
    up[a] += h, um[a] -= h;
    influence.Sed(up, plus);
    influence.Sed(um, minus);
    EXPECT_LE((J.col(a) - (plus - minus) / (2 * h)).norm(), 1e-5 * J.col(a).norm()) << a;  // single precision
  }
}

// Pins: an offset, two knots with the slope falling after each (the skin stiffening) and
// every actuator crossing segments on the way. The intercept a render keeps is updated per
// actuator that changed segment (display_influence.h); after hundreds of such changes the
// SED must be what a fresh influence computes at the same commands.
TEST(DisplayInfluence, PiecewiseSedDoesNotDependOnThePathTaken) {
  ElementStrainInfluence in = testing::SyntheticInfluence(7, 45, 1e-3);
  in.command_offset = {0.0, 0.5, 1.0, 0.2, 0.0, 2.0, 0.7};
  in.knot_command = {2.0, 5.0};
  in.strain_at_knot = {2.0 * in.strain_per_command, 3.5 * in.strain_per_command};
  const DisplayInfluence walked(in);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> command(0.0, 9.0);
  Eigen::VectorXd u(7), sed, fresh_sed, jacobian_sed;
  Eigen::MatrixXd J, fresh_J;
  for (int step = 0; step < 600; ++step) {
    for (int i = 0; i < 7; ++i) u[i] = command(rng);
    walked.Sed(u, sed);
  }
  walked.SedAndJacobian(u, jacobian_sed, J);
  const DisplayInfluence fresh(in);
  fresh.SedAndJacobian(u, fresh_sed, fresh_J);
  EXPECT_LE((sed - fresh_sed).norm(), 1e-12 * fresh_sed.norm());
  EXPECT_LE((jacobian_sed - fresh_sed).norm(), 1e-12 * fresh_sed.norm());
  EXPECT_LE((J - fresh_J).norm(), 1e-12 * fresh_J.norm());
  // And both are the element SED of the piecewise strain, evaluated directly.
  Eigen::VectorXd eps = in.preload_strain;
  for (int i = 0; i < 7; ++i) {
    const double v = std::max(0.0, u[i] - in.command_offset[size_t(i)]);
    const double scale = v < 2.0 ? v : v < 5.0 ? 2.0 + 0.5 * (v - 2.0) : 3.5 + 0.5 * (v - 5.0);
    eps += scale * in.strain_per_command.col(i);
  }
  ElementStrainInfluence linear = in;
  linear.strain_per_command.setZero();
  linear.preload_strain = eps;
  EXPECT_LE((fresh_sed - DirectSed(linear, Eigen::VectorXd::Zero(7))).norm(), 1e-6 * fresh_sed.norm());
}

// Copies share the built tables (a hand's fingers each render with a copy): each copy keeps
// its own place on the curves, so copies walked alternately answer as a fresh influence does,
// piecewise (pins: the element kernel) and linear (the vertex forms).
TEST(DisplayInfluence, CopiesWalkedAlternatelyAnswerAsAFreshInfluence) {
  ElementStrainInfluence pins = testing::SyntheticInfluence(7, 45, 1e-3);
  pins.command_offset = {0.0, 0.5, 1.0, 0.2, 0.0, 2.0, 0.7};
  pins.knot_command = {2.0, 5.0};
  pins.strain_at_knot = {2.0 * pins.strain_per_command, 3.5 * pins.strain_per_command};
  for (const ElementStrainInfluence& in : {pins, testing::SyntheticInfluence(7, 45, 1e-3)}) {
    const DisplayInfluence original(in);
    const DisplayInfluence copy = original;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> command(0.0, 9.0);
    Eigen::VectorXd u(7), w(7), sed_u, sed_w, fresh_u, fresh_w;
    Eigen::MatrixXd J_u, J_w, fresh_J;
    for (int step = 0; step < 50; ++step) {
      for (int i = 0; i < 7; ++i) u[i] = command(rng), w[i] = command(rng);
      original.SedAndJacobian(u, sed_u, J_u);
      copy.SedAndJacobian(w, sed_w, J_w);
    }
    const DisplayInfluence fresh(in);
    fresh.SedAndJacobian(u, fresh_u, fresh_J);
    EXPECT_LE((sed_u - fresh_u).norm(), 1e-12 * fresh_u.norm());
    EXPECT_LE((J_u - fresh_J).norm(), 1e-12 * fresh_J.norm());
    fresh.SedAndJacobian(w, fresh_w, fresh_J);
    EXPECT_LE((sed_w - fresh_w).norm(), 1e-12 * fresh_w.norm());
    EXPECT_LE((J_w - fresh_J).norm(), 1e-12 * fresh_J.norm());
  }
}

TEST(DisplayInfluence, InconsistentSizesAreRefused) {
  ElementStrainInfluence in = testing::SyntheticInfluence(4, 10, 0.0);
  in.preload_strain.conservativeResize(7);
  EXPECT_THROW(DisplayInfluence{in}, std::invalid_argument);
  in = testing::SyntheticInfluence(4, 10, 0.0);
  in.vertex_element[3] = 99;
  EXPECT_THROW(DisplayInfluence{in}, std::invalid_argument);
  in = testing::SyntheticInfluence(4, 10, 0.0);
  in.strain_per_command(0, 0) = std::nan("");
  EXPECT_THROW(DisplayInfluence{in}, std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::render
