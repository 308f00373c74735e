// The non-parametric surface pressure (sensors/surface_pressure_inversion.h): a known load
// through the forward model comes back with its force and centre; the field is never
// negative, a NaN reading is a fault (no NaN out), zero readings give zero pressure.
#include "sensors/surface_pressure_inversion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "sensors/calibration_press.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {
namespace {

const SensorProfile& Uskin() {
  static const SensorProfile p = LoadNamedSensorProfile("uskin_4x4");
  return p;
}

// Readings of a uniform pressure over the square |x - cx|, |y - cy| <= half_mm carrying
// force_N, on the forward model's own (finer) load grid: not the inversion's cells.
Eigen::VectorXd UniformPatch(double cx, double cy, double half_mm, double force_N) {
  const TactileForwardModel model(Uskin(), Uskin().forward_model);
  std::vector<SurfaceLoad> loads;
  for (int c = 0; c < model.cell_count(); ++c) {
    const Eigen::Vector2d p = model.CellCentre_mm(c);
    if (std::abs(p.x() - cx) > half_mm || std::abs(p.y() - cy) > half_mm) continue;
    SurfaceLoad l;
    l.cell = c;
    loads.push_back(l);
  }
  for (auto& l : loads) l.normal_N = force_N / double(loads.size());
  Eigen::VectorXd r;
  model.Respond(loads, &r);
  return r;
}

// 2-count noise per reading, as the reconstruction's tests add it.
Eigen::VectorXd Noisy(Eigen::VectorXd r, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, 1);
  for (int k = 0; k < Uskin().taxel_count; ++k)
    for (int a = 0; a < 3; ++a) r[3 * k + a] += 2 * NewtonsPerCount(Uskin(), k, a) * n(rng);
  return r;
}

TEST(SurfacePressureInversion, AUniformPatchComesBackWithItsForceAndCentre) {
  SurfacePressureInversion inversion(Uskin());
  // 3 x 3 mm at (1.7, -2.3), 0.6 N; without noise and with the sensor's 2 counts.
  for (const bool noise : {false, true}) {
    const Eigen::VectorXd clean = UniformPatch(1.7, -2.3, 1.5, 0.6);
    const SurfacePressure& p = inversion.Solve(noise ? Noisy(clean, 7) : clean);
    ASSERT_TRUE(p.ok) << p.fault;
    std::printf("%s: force %.4f N, centre (%.3f, %.3f) mm, tangential %.4f N, rms %.2f sigma, %d cells, %d iterations, %d evaluations\n",
                noise ? "noisy" : "clean", p.normal_force_N, p.centroid_mm.x(), p.centroid_mm.y(), p.shear_N.norm(),
                p.rms_sigma, p.active_cells, p.iterations, p.evaluations);
    // Tolerances: clean 3 % of the force and 0.2 mm; with the sensor's noise 10 % and 0.5 mm
    // (a tenth of the 4.7 mm pitch): the field cannot pull, so positive noise far from the
    // patch reads as a little load, never negative noise as less.
    const double force_tol = noise ? 0.10 : 0.03, centre_tol_mm = noise ? 0.5 : 0.2;
    EXPECT_NEAR(p.normal_force_N, 0.6, force_tol * 0.6);
    EXPECT_NEAR(p.centroid_mm.x(), 1.7, centre_tol_mm);
    EXPECT_NEAR(p.centroid_mm.y(), -2.3, centre_tol_mm);
    EXPECT_LT(p.shear_N.norm(), force_tol * 0.6);
    EXPECT_LT(p.rms_sigma, noise ? 1.5 : 0.5);
  }
}

TEST(SurfacePressureInversion, TheFieldIsNeverNegative) {
  SurfacePressureInversion inversion(Uskin());
  // Pure noise and a patch with noise: no cell pulls.
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const Eigen::VectorXd r = Noisy(seed % 2 ? UniformPatch(-3, 2, 1, 0.3) : Eigen::VectorXd::Zero(48), seed);
    const SurfacePressure& p = inversion.Solve(r);
    ASSERT_TRUE(p.ok);
    EXPECT_GE(p.cell_force_N.minCoeff(), 0.0) << "seed " << seed;
    EXPECT_TRUE(p.cell_force_N.allFinite());
  }
}

TEST(SurfacePressureInversion, ANaNReadingIsAFaultAndNoNaNComesOut) {
  SurfacePressureInversion inversion(Uskin());
  // A 2 x 2 mm patch between the four middle taxels; taxel 0 (a corner) reads NaN.
  Eigen::VectorXd r = UniformPatch(0, 0, 1, 0.5);
  r[3 * 0 + 2] = std::numeric_limits<double>::quiet_NaN();
  const SurfacePressure& p = inversion.Solve(r);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.fault.find("taxel 0"), std::string::npos) << p.fault;
  EXPECT_TRUE(p.cell_force_N.allFinite());
  EXPECT_EQ(p.cell_force_N.sum(), 0.0);
  // The same taxel marked invalid is left out, and the rest answers.
  std::vector<uint8_t> valid(16, 1);
  valid[0] = 0;
  const SurfacePressure& q = inversion.Solve(r, valid);
  EXPECT_TRUE(q.ok) << q.fault;
  EXPECT_TRUE(q.cell_force_N.allFinite());
  EXPECT_NEAR(q.normal_force_N, 0.5, 0.05 * 0.5);
  // And the next clean scan is not spoiled by the fault.
  EXPECT_NEAR(inversion.Solve(UniformPatch(0, 0, 1, 0.5)).normal_force_N, 0.5, 0.05 * 0.5);
}

TEST(SurfacePressureInversion, ZeroReadingsGiveZeroPressure) {
  SurfacePressureInversion inversion(Uskin());
  inversion.Solve(UniformPatch(2, 2, 1, 0.8));  // a warm start that is no longer right
  const SurfacePressure& p = inversion.Solve(Eigen::VectorXd::Zero(48));
  ASSERT_TRUE(p.ok);
  EXPECT_EQ(p.cell_force_N.maxCoeff(), 0.0);
  EXPECT_EQ(p.normal_force_N, 0.0);
  EXPECT_EQ(p.shear_N.norm(), 0.0);
}

}  // namespace
}  // namespace sedbridge::sensors
