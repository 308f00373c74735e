#include "fem/rotation_extraction.h"

#include <gtest/gtest.h>

#include <random>

namespace sedbridge::fem {
namespace {

Eigen::Matrix3d RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

TEST(RotationExtraction, MatchesPolarDecompositionForStretchedRotations) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> s(0.5, 1.5);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Matrix3d Q = RandomRotation(rng);
    const Eigen::Matrix3d S = Q * Eigen::Vector3d(s(rng), s(rng), s(rng)).asDiagonal() * Q.transpose();
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
    const Eigen::Matrix3d Q = RandomRotation(rng);
    const Eigen::Matrix3d S = Q * Eigen::Vector3d(s(rng), s(rng), s(rng)).asDiagonal() * Q.transpose();
    Eigen::Quaterniond cold = Eigen::Quaterniond::Identity();
    EXPECT_LT((ExtractRotation(R * S, cold, 12) - R).norm(), 1e-11) << "trial " << trial;
    Eigen::Quaterniond warm(R);
    warm = warm * Eigen::Quaterniond(1.0, n(rng), n(rng), n(rng));
    warm.normalize();
    EXPECT_LT((ExtractRotation(R * S, warm, 3) - R).norm(), 1e-11) << "trial " << trial;
  }
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

}  // namespace
}  // namespace sedbridge::fem
