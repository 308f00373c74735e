// The simulated pads against the calibration rig's presses (config/sensors/rig_uskin_4x4/):
// the rig-fitted layer reproduces them within noise where the half-space and Winkler pads
// do not (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s1).
#include "sensors/simulated/pad_rig_check.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/resource_path.h"

namespace sedbridge::sensors {
namespace {

double WorstAxis(const PadPressReport& r) { return std::max({r.rms_sigma[0], r.rms_sigma[1], r.rms_sigma[2]}); }

TEST(PadRigCheck, RigFittedLayerReproducesThePressesTheOtherPadsMiss) {
  const SensorProfile p = LoadNamedSensorProfile("uskin_4x4");
  auto presses = LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), p);
  ASSERT_EQ(presses.size(), 30u);
  presses.resize(21);  // 00-20: the presses the layer pad was fitted to
  const auto layer = EvaluatePadOnPresses(presses, p, RigFittedLayerPad());
  PadModel half_space;
  half_space.mechanics = PadMechanics::kHalfSpace;
  const auto hs = EvaluatePadOnPresses(presses, p, half_space);
  PadModel winkler = half_space;
  winkler.mechanics = PadMechanics::kKernel;
  const auto kernel = EvaluatePadOnPresses(presses, p, winkler);
  int layer_within = 0, hs_within = 0, kernel_within = 0;
  for (size_t i = 0; i < presses.size(); ++i) {
    ASSERT_TRUE(layer[i].reached && hs[i].reached && kernel[i].reached) << presses[i].name;
    layer_within += WorstAxis(layer[i]) < 1;
    // At light load (the ramp at 0.29 of the force) the layer reproduces every press.
    const double* ramp = layer[i].ramp_rms_sigma;
    EXPECT_LT(std::max({ramp[0], ramp[1], ramp[2]}), 1.0) << presses[i].name;
    hs_within += WorstAxis(hs[i]) < 1;
    kernel_within += WorstAxis(kernel[i]) < 1;
  }
  EXPECT_GE(layer_within, 19);
  EXPECT_LE(hs_within, 12);
  EXPECT_LE(kernel_within, 9);
  // The flats (presses 17, 18): uniform on the rig and under the layer, edge-loaded on the
  // half-space; spheres of 2.5 mm (00-02): Hertz on the rig and the layer, too wide on
  // Winkler's foundation.
  for (int i : {17, 18}) {
    EXPECT_LT(WorstAxis(layer[size_t(i)]), 1.0) << presses[size_t(i)].name;
    EXPECT_GT(WorstAxis(hs[size_t(i)]), 3.0) << presses[size_t(i)].name;
  }
  for (int i : {0, 1, 2}) EXPECT_LT(WorstAxis(layer[size_t(i)]), WorstAxis(kernel[size_t(i)])) << presses[size_t(i)].name;
}

TEST(PadRigCheck, RefusesAPadWithoutKernels) {
  const SensorProfile p = LoadNamedSensorProfile("uskin_4x4");
  PadModel winkler;
  winkler.mechanics = PadMechanics::kWinkler;
  EXPECT_THROW(EvaluatePadOnPresses({}, p, winkler), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::sensors
