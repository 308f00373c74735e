#pragma once
// What the contact tests share: the shipped uSkin profile, the calibrated model's readings of
// contacts pressed at once, single-scan noise, and a hold of noisy scans.

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <vector>

#include "contact/contact_reconstruction.h"
#include "sensors/sensor_profile.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::contact::test_support {

inline const sensors::SensorProfile& Uskin() {
  static const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  return p;
}

// A sphere of radius r_mm whose lowest point is at (x_mm, y_mm), pressed with force_N.
inline sensors::ContactPrimitive SphereAt(double x_mm, double y_mm, double r_mm, double force_N) {
  sensors::ContactPrimitive c;
  c.x_mm = x_mm, c.y_mm = y_mm, c.radius_mm = r_mm, c.normal_force_N = force_N;
  return c;
}

// The calibrated model's readings of contacts pressed at once (the sensor is linear in the
// surface load: the readings add).
inline Eigen::VectorXd ReadingsOf(std::initializer_list<sensors::ContactPrimitive> contacts) {
  static const sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(3 * Uskin().taxel_count), one;
  for (const sensors::ContactPrimitive& c : contacts) {
    model.Predict(c, &one);
    sum += one;
  }
  return sum;
}

// The reconstruction's single-scan noise (2 counts: 0.5 mN normal, 0.2 mN shear per count).
inline Eigen::VectorXd Noisy(const Eigen::VectorXd& r, std::mt19937_64* rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::VectorXd out = r;
  for (Eigen::Index i = 0; i < out.size(); ++i) out[i] += n(*rng) * 2 * (i % 3 == 2 ? 0.0005 : 0.0002);
  return out;
}

// The estimate after `scans` noisy scans of the same readings (all taxels valid): a hold.
inline ContactEstimate HeldFor(ContactReconstructor* r, const Eigen::VectorXd& reading, std::mt19937_64* rng,
                               int scans = 40) {
  ContactEstimate e;
  for (int k = 0; k < scans; ++k) e = r->Reconstruct(Noisy(reading, rng), std::vector<uint8_t>(16, 1));
  return e;
}

}  // namespace sedbridge::contact::test_support
