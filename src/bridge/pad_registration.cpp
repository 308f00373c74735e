#include "bridge/pad_registration.h"

#include <cmath>
#include <stdexcept>

namespace sedbridge::bridge {

PadRegistration::PadRegistration(const std::vector<sensors::TaxelPosition>& taxels, PadRegistrationParams params)
    : params_(params) {
  if (!(std::isfinite(params.scale) && params.scale > 0))
    throw std::invalid_argument("registration scale must be finite and > 0");
  if (!params.offset_mm.allFinite() || !std::isfinite(params.rotation_deg))
    throw std::invalid_argument("registration offset and rotation must be finite");
  for (const auto& t : taxels) centroid_mm_ += Eigen::Vector2d(t.x_mm, t.y_mm);
  if (!taxels.empty()) centroid_mm_ /= static_cast<double>(taxels.size());
  const double a = params.rotation_deg * M_PI / 180.0;
  rotation_ << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
}

Eigen::Vector2d PadRegistration::ToPad(const Eigen::Vector2d& sensor_mm) const {
  return params_.offset_mm + params_.scale * (rotation_ * (sensor_mm - centroid_mm_));
}

Eigen::Vector2d PadRegistration::ToSensor(const Eigen::Vector2d& pad_mm) const {
  return centroid_mm_ + rotation_.transpose() * (pad_mm - params_.offset_mm) / params_.scale;
}

}  // namespace sedbridge::bridge
