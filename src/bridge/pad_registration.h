#pragma once
// Registration of the follower's sensor pad onto the leader model's pad frame: a 2-D affine
// map in the pad plane (the sensor is flat, the model's pad frame has z along the outward pad
// normal, so only x-y are mapped).
//
//   p_pad = offset + scale * R(rotation) * (p_sensor - centroid)
//
// `centroid` is the mean of the sensor's taxel centres, so the default (offset 0, rotation 0,
// scale 1) puts the sensor's centre on the pad-frame origin (where the paper's tilted plane
// first touches) with the sensor's x along the pad's x.

#include <Eigen/Core>
#include <vector>

#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

struct PadRegistrationParams {
  Eigen::Vector2d offset_mm = Eigen::Vector2d::Zero();  ///< where the sensor centre lands [mm, pad frame]
  double rotation_deg = 0;  ///< counter-clockwise about the pad normal (+z_pad) [deg]
  double scale = 1;         ///< sensor mm -> pad mm (> 0); taxel areas scale by scale^2
};

class PadRegistration {
 public:
  /// @param[in] taxels  taxel centres on the sensor pad [mm] (sensors::SensorProfile::taxels)
  /// @param[in] params  throws std::invalid_argument for a non-finite or non-positive scale
  PadRegistration(const std::vector<sensors::TaxelPosition>& taxels, PadRegistrationParams params = {});

  /// Sensor-pad point [mm] -> pad-frame x-y [mm].
  Eigen::Vector2d ToPad(const Eigen::Vector2d& sensor_mm) const;
  /// Pad-frame x-y [mm] -> sensor-pad point [mm] (inverse of ToPad).
  Eigen::Vector2d ToSensor(const Eigen::Vector2d& pad_mm) const;
  /// A sensor-frame in-plane vector (e.g. shear traction) rotated into the pad frame (no
  /// scaling: tractions keep their magnitude).
  Eigen::Vector2d RotateToPad(const Eigen::Vector2d& v_sensor) const { return rotation_ * v_sensor; }

  const PadRegistrationParams& params() const { return params_; }
  const Eigen::Vector2d& centroid_mm() const { return centroid_mm_; }
  const Eigen::Matrix2d& rotation() const { return rotation_; }

 private:
  PadRegistrationParams params_;
  Eigen::Vector2d centroid_mm_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d rotation_ = Eigen::Matrix2d::Identity();
};

}  // namespace sedbridge::bridge
