// Pressure boundary condition on the coarse model: exact force balance, zero traction outside
// the sensor footprint, shear, the NaN guard of the scan conditioning.

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "bridge/pressure_boundary_condition.h"
#include "bridge/scene_fe_step.h"
#include "bridge/taxel_values.h"
#include "bridge_test_util.h"

namespace sedbridge::bridge {
namespace {

class TractionFieldTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    profile_ = new sensors::SensorProfile(sensors::LoadNamedSensorProfile("uskin_4x4"));
    step_ = new SceneFeStep(BridgeSceneDescription("B_coarse", "fast"), *profile_, PadRegistration(profile_->taxels));
  }
  static void TearDownTestSuite() {
    delete step_;
    delete profile_;
  }
  static sensors::SensorProfile* profile_;
  static SceneFeStep* step_;
};
sensors::SensorProfile* TractionFieldTest::profile_ = nullptr;
SceneFeStep* TractionFieldTest::step_ = nullptr;

TEST_F(TractionFieldTest, EveryTaxelReachesTheCoarseModel) {
  const TractionWeights& f = step_->boundary_condition().field();
  EXPECT_TRUE(f.unmapped_taxels.empty());
  EXPECT_GT(f.loaded_nodes.size(), 20u);
  EXPECT_NEAR(f.sigma_mm, 0.5 * 4.7, 1e-9);
}

TEST_F(TractionFieldTest, IntegratedNodalForceEqualsMeasuredForceExactly) {
  PressureBoundaryCondition bc(step_->scene(), *profile_, PadRegistration(profile_->taxels));
  const ScanConditioner cond(*profile_, PadRegistration(profile_->taxels));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> p(0, 20e3), s(-3e3, 3e3);
  const Eigen::Matrix3d R_pad = step_->scene().model().pad_frame.model_from_pad.linear().transpose();
  for (int trial = 0; trial < 5; ++trial) {
    sensors::Scan scan = testing::UniformScan(*profile_, 0.0);
    for (int i = 0; i < profile_->taxel_count; ++i) {
      scan.pressure_Pa[size_t(i)] = trial == 0 ? 5e3 : p(rng);
      scan.shear_x_Pa[size_t(i)] = s(rng);
      scan.shear_y_Pa[size_t(i)] = s(rng);
    }
    TaxelValues v;
    ASSERT_TRUE(cond.Condition(scan, &v).usable);
    double measured = 0, sx = 0, sy = 0;
    for (int i = 0; i < profile_->taxel_count; ++i) {
      const double a = profile_->taxel_area_mm2() * 1e-6;
      measured += scan.pressure_Pa[size_t(i)] * a;
      sx += scan.shear_x_Pa[size_t(i)] * a;
      sy += scan.shear_y_Pa[size_t(i)] * a;
    }
    EXPECT_NEAR(v.total_force_N, measured, 1e-12 * measured);
    step_->scene().traction()->SetNodalTraction(bc.Apply(v));
    const Eigen::Vector3d f_pad = R_pad * step_->scene().traction()->TotalForce();
    EXPECT_NEAR(-f_pad.z(), measured, 1e-9 * measured) << "trial " << trial;
    EXPECT_NEAR(f_pad.x(), sx, 1e-9 * measured);
    EXPECT_NEAR(f_pad.y(), sy, 1e-9 * measured);
  }
  step_->scene().traction()->ClearTraction();
}

TEST_F(TractionFieldTest, ZeroLoadOutsideTheFootprint) {
  const SkinNodes nodes = SkinNodesOf(step_->scene());
  const PadRegistration reg(profile_->taxels);
  TaxelValues v;
  v.pressure_Pa.assign(16, 10e3);
  TractionFieldOptions consistent;
  consistent.nodal_load = NodalLoad::kConsistent;
  PressureBoundaryCondition bc_consistent(step_->scene(), *profile_, reg, consistent);
  PressureBoundaryCondition bc_lumped(step_->scene(), *profile_, reg);  // default: lumped
  const Eigen::Matrix3Xd t = bc_consistent.Apply(v);
  const Eigen::Matrix3Xd t_pad = bc_consistent.traction_pad_Pa();
  fem::SurfaceTractionForce& tr = *step_->scene().traction();
  tr.SetNodalTraction(bc_lumped.Apply(v));
  const Eigen::Matrix3Xd f_lumped = tr.NodalForces();
  tr.ClearTraction();
  const double f_scale = f_lumped.cwiseAbs().maxCoeff();
  int outside = 0, inside_loaded = 0;
  for (Eigen::Index n = 0; n < t.cols(); ++n) {
    const Eigen::Vector2d s = reg.ToSensor(nodes.position_pad_mm.col(n).head<2>());
    if (!InsideFootprint(*profile_, s)) {
      ++outside;
      // Consistent: the traction itself is zero; lumped: the nodal forces are.
      EXPECT_EQ(t.col(n).norm(), 0.0) << "node " << n;
      EXPECT_EQ(bc_consistent.applied_weights().row(n).nonZeros(), 0);
      EXPECT_LT(f_lumped.col(n).norm(), 1e-9 * f_scale) << "node " << n;
    } else if (t.col(n).norm() > 0) {
      ++inside_loaded;
      EXPECT_GE(nodes.normal_pad(2, n), 0.5);  // only skin facing the pad
      // Lumped: each loaded node carries exactly its area times the interpolated pressure.
      const Eigen::Vector3d f_pad =
          step_->scene().model().pad_frame.model_from_pad.linear().transpose() * f_lumped.col(n);
      EXPECT_NEAR(f_pad.z(), nodes.area_m2[n] * t_pad(2, n), 1e-9 * f_scale);
    }
  }
  EXPECT_GT(outside, 100);  // most of the finger (back, nail side, proximal cut)
  EXPECT_GT(inside_loaded, 20);
}

TEST_F(TractionFieldTest, AppliedWeightsMapEachAxisOfTheTaxelValuesToTheTraction) {
  PressureBoundaryCondition bc(step_->scene(), *profile_, PadRegistration(profile_->taxels));
  TaxelValues v;
  for (int i = 0; i < 16; ++i) {
    v.pressure_Pa.push_back(1e3 * (i + 1));
    v.shear_x_Pa.push_back(100.0 * (i % 5) - 200);
    v.shear_y_Pa.push_back(50.0 * (i % 3) + 10);
  }
  bc.Apply(v);
  const Eigen::Matrix3Xd& t_pad = bc.traction_pad_Pa();
  const auto& w = bc.applied_weights();
  ASSERT_EQ(w.rows(), t_pad.cols());
  ASSERT_EQ(w.cols(), 16);
  auto as_vector = [](const std::vector<double>& x) { return Eigen::Map<const Eigen::VectorXd>(x.data(), Eigen::Index(x.size())); };
  const Eigen::VectorXd shear_x = w * as_vector(v.shear_x_Pa);
  const Eigen::VectorXd shear_y = w * as_vector(v.shear_y_Pa);
  const Eigen::VectorXd normal = w * as_vector(v.pressure_Pa);
  const double scale = t_pad.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  EXPECT_LT((t_pad.row(0).transpose() - shear_x).cwiseAbs().maxCoeff(), 1e-9 * scale);
  EXPECT_LT((t_pad.row(1).transpose() - shear_y).cwiseAbs().maxCoeff(), 1e-9 * scale);
  EXPECT_LT((t_pad.row(2).transpose() + normal).cwiseAbs().maxCoeff(), 1e-9 * scale);  // pressure pushes inward
}

TEST_F(TractionFieldTest, MovingTheSensorOffThePadLeavesItsTaxelsUnmapped) {
  PadRegistrationParams far;
  far.offset_mm = {40, 0};
  const TractionWeights w =
      BuildTractionWeights(*profile_, PadRegistration(profile_->taxels, far), SkinNodesOf(step_->scene()));
  EXPECT_EQ(w.unmapped_taxels.size(), 16u);
  EXPECT_EQ(w.W.nonZeros(), 0);
}

TEST(ScanConditioner, NanInAValidTaxelIsCountedAndFilledFromNeighbours) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  const ScanConditioner cond(p, PadRegistration(p.taxels));
  sensors::Scan scan = testing::UniformScan(p, 2000.0);
  scan.pressure_Pa[5] = std::nan("");
  scan.shear_x_Pa[6] = INFINITY;
  TaxelValues v;
  const ConditioningReport r = cond.Condition(scan, &v);
  EXPECT_TRUE(r.usable);
  EXPECT_EQ(r.nonfinite_values, 2);
  EXPECT_EQ(r.invalid_taxels, 2);
  EXPECT_NEAR(v.pressure_Pa[5], 2000.0, 1e-9);  // uniform neighbours -> the same value
  EXPECT_NEAR(v.pressure_Pa[6], 2000.0, 1e-9);
  for (double x : v.pressure_Pa) EXPECT_TRUE(std::isfinite(x));
  for (double x : v.shear_x_Pa) EXPECT_TRUE(std::isfinite(x));
}

TEST(ScanConditioner, ZeroPolicyAndNoiseFloor) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  ScanConditioningOptions o;
  o.invalid = InvalidTaxelPolicy::kZero;
  o.noise_floor_Pa = 100;
  const ScanConditioner cond(p, PadRegistration(p.taxels), o);
  sensors::Scan scan = testing::UniformScan(p, 2000.0);
  scan.valid[3] = 0;
  scan.pressure_Pa[4] = 50;   // below the floor
  scan.pressure_Pa[7] = -500; // a pad cannot pull
  TaxelValues v;
  ASSERT_TRUE(cond.Condition(scan, &v).usable);
  EXPECT_EQ(v.pressure_Pa[3], 0.0);
  EXPECT_EQ(v.pressure_Pa[4], 0.0);
  EXPECT_EQ(v.pressure_Pa[7], 0.0);
  EXPECT_NEAR(v.total_force_N, 13 * 2000.0 * 16e-6, 1e-12);
}

TEST(ScanConditioner, RejectsMostlyInvalidOrMisshapenScans) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  const ScanConditioner cond(p, PadRegistration(p.taxels));
  TaxelValues v;
  sensors::Scan scan = testing::UniformScan(p, 1000.0);
  for (int i = 0; i < 9; ++i) scan.pressure_Pa[size_t(i)] = std::nan("");
  const ConditioningReport r = cond.Condition(scan, &v);
  EXPECT_FALSE(r.usable);
  EXPECT_EQ(r.nonfinite_values, 9);
  sensors::Scan shorter = testing::UniformScan(p, 1000.0);
  shorter.pressure_Pa.pop_back();
  EXPECT_FALSE(cond.Condition(shorter, &v).usable);
}

}  // namespace
}  // namespace sedbridge::bridge

namespace sedbridge::bridge {
namespace {

// Found by adversarial review: with many frames lost, filled taxels must not raise the peak.
// A peaked contact, 7 of 16 taxels invalid at random: every filled value is at most its
// weakest valid adjacent taxel (0 without one), so no filled value exceeds the valid peak.
TEST(ScanConditioner, FillNeverExceedsWhatValidNeighboursSupport) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  ScanConditioningOptions options;
  options.max_invalid_fraction = 0.6;
  const ScanConditioner cond(p, PadRegistration(p.taxels), options);
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    sensors::Scan scan = testing::UniformScan(p, 0.0);
    for (int k = 0; k < 16; ++k) {
      const double dx = p.taxels[size_t(k)].x_mm - 2.35, dy = p.taxels[size_t(k)].y_mm - 2.35;
      scan.pressure_Pa[size_t(k)] = 20000.0 * std::exp(-(dx * dx + dy * dy) / 8.0);
    }
    std::vector<int> order(16);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    for (int k = 0; k < 7; ++k) scan.valid[size_t(order[size_t(k)])] = 0, scan.flags[size_t(order[size_t(k)])] = 1;
    TaxelValues v;
    ASSERT_TRUE(cond.Condition(scan, &v).usable);
    double valid_peak = 0;
    for (int k = 0; k < 16; ++k)
      if (scan.valid[size_t(k)]) valid_peak = std::max(valid_peak, v.pressure_Pa[size_t(k)]);
    for (int k = 0; k < 16; ++k) {
      if (scan.valid[size_t(k)]) continue;
      double support = INFINITY;
      for (int j = 0; j < 16; ++j)
        if (scan.valid[size_t(j)] && j != k &&
            std::hypot(p.taxels[size_t(k)].x_mm - p.taxels[size_t(j)].x_mm,
                       p.taxels[size_t(k)].y_mm - p.taxels[size_t(j)].y_mm) <= 1.5 * 4.7)
          support = std::min(support, v.pressure_Pa[size_t(j)]);
      EXPECT_LE(v.pressure_Pa[size_t(k)], std::isfinite(support) ? support : 0.0) << "trial " << trial << " taxel " << k;
      EXPECT_LE(v.pressure_Pa[size_t(k)], valid_peak);
    }
  }
}

}  // namespace
}  // namespace sedbridge::bridge
