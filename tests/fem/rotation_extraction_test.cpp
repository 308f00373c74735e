#include "fem/rotation_extraction.h"

#include "fem/strain_energy_density.h"
#include "fem/tet_element.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

namespace sedbridge::fem {
namespace {

Eigen::Matrix3d RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

// A symmetric stretch Q diag(s1, s2, s3) Q^T, Q random, each s drawn from `s`.
Eigen::Matrix3d RandomStretch(std::mt19937& rng, std::uniform_real_distribution<double>& s) {
  const Eigen::Matrix3d Q = RandomRotation(rng);
  return Q * Eigen::Vector3d(s(rng), s(rng), s(rng)).asDiagonal() * Q.transpose();
}

// R turned by a small random rotation (each quaternion component drawn from `n`), as a
// warm start.
Eigen::Quaterniond Perturbed(const Eigen::Matrix3d& R, std::mt19937& rng, std::normal_distribution<double>& n) {
  Eigen::Quaterniond q(R);
  q = q * Eigen::Quaterniond(1.0, n(rng), n(rng), n(rng));
  return q.normalized();
}

TEST(RotationExtraction, MatchesPolarDecompositionForStretchedRotations) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> s(0.5, 1.5);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Matrix3d S = RandomStretch(rng, s);
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    const Eigen::Matrix3d got = ExtractRotation(R * S, q, 100);
    EXPECT_LT((got - R).norm(), 1e-6) << "trial " << trial;
    EXPECT_LT((PolarRotationSvd(R * S) - R).norm(), 1e-9);
  }
}

TEST(RotationExtraction, ConvergesQuadraticallyToRoundOff) {
  // Newton's step: from a cold start (identity) a moderately stretched rotation is found to
  // round-off in a handful of iterations; warm-started from a nearby rotation, in 3.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> s(0.8, 1.2);
  std::normal_distribution<double> n(0.0, 1e-3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Matrix3d S = RandomStretch(rng, s);
    Eigen::Quaterniond cold = Eigen::Quaterniond::Identity();
    EXPECT_LT((ExtractRotation(R * S, cold, 12) - R).norm(), 1e-11) << "trial " << trial;
    Eigen::Quaterniond warm = Perturbed(R, rng, n);
    EXPECT_LT((ExtractRotation(R * S, warm, 3) - R).norm(), 1e-11) << "trial " << trial;
  }
}

TEST(RotationExtraction, StopsAfterANewtonStepBelowItsBound) {
  // Warm-started ~1e-3 rad away: the first Newton step (~1e-3 rad) leaves an error far
  // below 1e-6 rad, so the second step is below the default bound and the last one; a
  // bound above the first step stops after it.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> s(0.8, 1.2);
  std::normal_distribution<double> n(0.0, 1e-3);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Matrix3d F = R * RandomStretch(rng, s);
    const Eigen::Quaterniond start = Perturbed(R, rng, n);
    Eigen::Quaterniond q1 = start, q2 = start, q20 = start, loose = start;
    const Eigen::Matrix3d r1 = ExtractRotation(F, q1, 1);
    const Eigen::Matrix3d r2 = ExtractRotation(F, q2, 2);
    const Eigen::Matrix3d r20 = ExtractRotation(F, q20, 20);
    EXPECT_LT((r1 - R).norm(), 1e-6) << "trial " << trial;
    EXPECT_LT((r2 - R).norm(), 1e-13) << "trial " << trial;
    EXPECT_EQ((r2 - r20).norm(), 0.0) << "trial " << trial;  // stopped after the second step
    EXPECT_EQ((ExtractRotation(F, loose, 20, 1e-2) - r1).norm(), 0.0) << "trial " << trial;
  }
}

TEST(RotationExtraction, SedIsStationaryInTheRotation) {
  // Why the SED may take a rotation to 1e-3 rad per Newton step: at the polar R, turning R by
  // d rad moves the corotational strain by O(d) but the SED only by O(d^2).
  TetMesh mesh;
  mesh.rest_positions_m.resize(3, 4);
  mesh.rest_positions_m << 0, 1e-3, 0, 0, 0, 0, 1e-3, 0, 0, 0, 0, 1e-3;
  mesh.tets = {{0, 1, 2, 3}};
  mesh.materials = {LinearElasticMaterial{"skin", 1e5, 0.45, 1100}};
  mesh.tet_material = {0};
  const TetElement e = PrecomputeElements(mesh)[0];
  std::mt19937 rng(7);
  const Eigen::Matrix3d R = RandomRotation(rng);
  Eigen::Matrix3d S;
  S << 1.05, 0.02, -0.01, 0.02, 0.97, 0.015, -0.01, 0.015, 1.01;
  const Eigen::Matrix3d F = R * S;
  const double sed = ElementSed(e, F, R);
  ASSERT_GT(sed, 100.0);
  double sed_change[2], strain_change[2];
  for (int k = 0; k < 2; ++k) {
    const double d = k == 0 ? 1e-3 : 1e-4;
    const Eigen::Matrix3d turned = R * Eigen::AngleAxisd(d, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
    const Eigen::Matrix3d G = turned.transpose() * F, G0 = R.transpose() * F;
    strain_change[k] = (0.5 * (G + G.transpose()) - 0.5 * (G0 + G0.transpose())).norm();
    sed_change[k] = std::abs(ElementSed(e, F, turned) - sed);
  }
  // A tenth of the angle: a tenth of the strain change (first order), a hundredth of the
  // SED change (second order).
  EXPECT_NEAR(strain_change[0] / strain_change[1], 10.0, 0.5);
  EXPECT_NEAR(sed_change[0] / sed_change[1], 100.0, 5.0);
  EXPECT_LT(sed_change[0], 1e-4 * sed);
}

TEST(RotationExtraction, InvertedAndDegenerateGiveProperRotations) {
  std::mt19937 rng(2);
  const Eigen::Matrix3d cases[] = {
      Eigen::Vector3d(1, 1, -0.5).asDiagonal(),  // inverted (flattened through itself)
      Eigen::Vector3d(1, 1, 0).asDiagonal(),     // zero volume
      Eigen::Matrix3d::Zero(),                   // collapsed to a point
      -Eigen::Matrix3d::Identity(),              // point reflection
  };
  for (const auto& F : cases) {
    for (int k = 0; k < 10; ++k) {
      Eigen::Quaterniond q(RandomRotation(rng));
      const Eigen::Matrix3d R = ExtractRotation(RandomRotation(rng) * F, q);
      EXPECT_TRUE(R.allFinite());
      EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
      EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-9);
    }
    EXPECT_NEAR(PolarRotationSvd(F).determinant(), 1.0, 1e-9);
  }
}

TEST(RotationExtraction, NanInputFallsBackToIdentity) {
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 0) = std::nan("");
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  EXPECT_TRUE(ExtractRotation(F, q).allFinite());
}

// ExtractRotations (four at a time in vector registers, ExtractRotation for the rest) gives
// ExtractRotation's rotations and warm starts to round-off, on a batch that mixes warm
// starts a tiny step away (one vector step), a step between 1e-4 and the bound and far ones
// (ExtractRotation), an inverted F, a NaN and a count that is not a multiple of four; and
// takes ExtractRotation only where it must.
TEST(RotationExtraction, BatchedEqualsOneByOne) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> s(0.9, 1.1);
  std::normal_distribution<double> tiny(0.0, 5e-6), mid(0.0, 2e-4), far(0.0, 0.3);
  const int count = 43;
  std::vector<Eigen::Matrix3d> F(count), R(count);
  std::vector<Eigen::Quaterniond> q(count), q_reference(count);
  int expected_scalar = count % 4;
  for (int k = 0; k < count; ++k) {
    const Eigen::Matrix3d rotation = RandomRotation(rng);
    F[size_t(k)] = rotation * RandomStretch(rng, s);
    std::normal_distribution<double>& n = k % 7 == 3 ? far : (k % 7 == 5 ? mid : tiny);
    // The polar rotation's quaternion, then the warm start a small turn away.
    Eigen::Quaterniond polar = Eigen::Quaterniond::Identity();
    ExtractRotation(F[size_t(k)], polar, 50, 1e-12);
    q[size_t(k)] = Perturbed(polar.toRotationMatrix(), rng, n);
  }
  F[10] = -F[10];                                       // inverted
  F[20](1, 1) = std::numeric_limits<double>::quiet_NaN();  // bad input
  q_reference = q;
  const int scalar = ExtractRotations(count, F.data(), q.data(), R.data(), 1e-3);
  int vector_steps = 0;
  for (int k = 0; k < count; ++k) {
    const Eigen::Matrix3d expected = ExtractRotation(F[size_t(k)], q_reference[size_t(k)], 20, 1e-3);
    if (k == 20) {
      EXPECT_TRUE(R[size_t(k)].allFinite());
      continue;
    }
    EXPECT_LT((R[size_t(k)] - expected).norm(), 1e-14) << k;
    EXPECT_LT((q[size_t(k)].coeffs() - q_reference[size_t(k)].coeffs()).norm(), 1e-14) << k;
    if (k < count / 4 * 4 && k % 7 != 3 && k % 7 != 5 && k != 10) ++vector_steps;
  }
  EXPECT_LE(scalar, count - vector_steps);
  EXPECT_GE(scalar, expected_scalar + 1);  // the remainder, the far ones, the NaN
  EXPECT_LT(scalar, count / 2);
}

}  // namespace
}  // namespace sedbridge::fem
