#include "contact/contact_parameters.h"

#include <algorithm>
#include <cmath>

namespace sedbridge::contact {

using sensors::ContactPrimitive;
using sensors::ContactShape;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The shape's own unknowns (no shear) appended at u[*i]. Sphere: x, y, log R, log F;
// cylinder: offset of the axis from the pad centre along its normal, yaw, log R, (a finite
// rod: its centre along the axis, log half-length,) log F; flat: log F.
void AppendShapeUnknowns(const ContactPrimitive& p, Eigen::VectorXd* u, int* i) {
  switch (p.shape) {
    case ContactShape::kSphere:
      (*u)[(*i)++] = p.x_mm;
      (*u)[(*i)++] = p.y_mm;
      (*u)[(*i)++] = std::log(p.radius_mm);
      break;
    case ContactShape::kCylinder: {
      const double yaw = p.yaw_deg * kPi / 180;
      (*u)[(*i)++] = -p.x_mm * std::sin(yaw) + p.y_mm * std::cos(yaw);
      (*u)[(*i)++] = yaw;
      (*u)[(*i)++] = std::log(p.radius_mm);
      if (IsFiniteRod(p)) {
        (*u)[(*i)++] = p.x_mm * std::cos(yaw) + p.y_mm * std::sin(yaw);
        (*u)[(*i)++] = std::log(0.5 * p.length_mm);
      }
      break;
    }
    case ContactShape::kRoundPunch:
      (*u)[(*i)++] = p.x_mm;
      (*u)[(*i)++] = p.y_mm;
      (*u)[(*i)++] = std::log(p.radius_mm);
      break;
    case ContactShape::kPunch:
      (*u)[(*i)++] = p.x_mm;
      (*u)[(*i)++] = p.y_mm;
      (*u)[(*i)++] = std::log(p.half_size_mm[0]);
      (*u)[(*i)++] = std::log(p.half_size_mm[1]);
      (*u)[(*i)++] = p.yaw_deg * kPi / 180;
      break;
    case ContactShape::kCorner:
      (*u)[(*i)++] = p.x_mm;
      (*u)[(*i)++] = p.y_mm;
      break;
    case ContactShape::kFlat: break;
  }
  (*u)[(*i)++] = std::log(std::max(p.normal_force_N, 1e-6));
}

}  // namespace

bool IsFiniteRod(const ContactPrimitive& p) { return p.shape == ContactShape::kCylinder && p.length_mm > 0; }

int UnknownCount(ContactShape s, bool pair, bool finite, bool shear) {
  const int base = pair                       ? 2 * kSphereUnknowns
                   : s == ContactShape::kFlat  ? 1
                   : s == ContactShape::kPunch ? kPunchUnknowns
                   : s == ContactShape::kRoundPunch ? kRoundPunchUnknowns
                   : s == ContactShape::kCorner ? kCornerUnknowns
                   : finite                    ? 6
                                               : 4;
  return base + (shear ? 2 : 0);
}

ContactPrimitive ShapeFromUnknowns(ContactShape shape, bool finite, const double* u) {
  ContactPrimitive p;
  p.shape = shape;
  int i = 0;
  switch (shape) {
    case ContactShape::kSphere:
      p.x_mm = u[i++];
      p.y_mm = u[i++];
      p.radius_mm = std::exp(std::clamp(u[i++], -5.0, 6.0));
      break;
    case ContactShape::kCylinder: {
      const double s = u[i++], yaw = u[i++];
      p.x_mm = -s * std::sin(yaw);
      p.y_mm = s * std::cos(yaw);
      // Rods are axes, not arrows: report the yaw in [-90, 90).
      double deg = std::remainder(yaw * 180 / kPi, 180.0);
      if (deg >= 90) deg -= 180;
      p.yaw_deg = deg;
      p.radius_mm = std::exp(std::clamp(u[i++], -5.0, 6.0));
      if (finite) {
        const double along = u[i++];
        p.x_mm += along * std::cos(yaw);
        p.y_mm += along * std::sin(yaw);
        p.length_mm = 2 * std::exp(std::clamp(u[i++], std::log(kMinHalfLength_mm), std::log(kMaxHalfLength_mm)));
      }
      break;
    }
    case ContactShape::kPunch: {
      p.x_mm = u[i++];
      p.y_mm = u[i++];
      for (double& half : p.half_size_mm)
        half = std::exp(std::clamp(u[i++], std::log(kMinPunchHalfSize_mm), std::log(kMaxPunchHalfSize_mm)));
      // A rectangle turned by 180 deg is itself: its yaw in [-90, 90).
      double deg = std::remainder(u[i++] * 180 / kPi, 180.0);
      if (deg >= 90) deg -= 180;
      p.yaw_deg = deg;
      p.radius_mm = 0;
      break;
    }
    case ContactShape::kRoundPunch:
      p.x_mm = u[i++];
      p.y_mm = u[i++];
      p.radius_mm = std::exp(std::clamp(u[i++], std::log(kMinPunchHalfSize_mm), std::log(kMaxPunchHalfSize_mm)));
      break;
    case ContactShape::kCorner:
      p.x_mm = u[i++];
      p.y_mm = u[i++];
      p.radius_mm = 0;
      break;
    case ContactShape::kFlat: p.radius_mm = 0; break;
  }
  p.normal_force_N = std::exp(std::clamp(u[i++], -20.0, 5.0));
  return p;
}

// Unknowns <-> hypothesis: the shape's unknowns (a pair: both spheres'), then T_x, T_y [N].
Eigen::VectorXd ToUnknowns(const Hypothesis& h, bool shear) {
  Eigen::VectorXd u(UnknownCount(h.first.shape, h.pair, IsFiniteRod(h.first), shear));
  int i = 0;
  AppendShapeUnknowns(h.first, &u, &i);
  if (h.pair) AppendShapeUnknowns(h.second, &u, &i);
  if (shear) {
    u[i++] = h.first.shear_x_N;
    u[i++] = h.first.shear_y_N;
  }
  return u;
}

Hypothesis FromUnknowns(ContactShape shape, bool pair, bool finite, const Eigen::VectorXd& u, bool shear) {
  Hypothesis h;
  h.pair = pair;
  h.first = ShapeFromUnknowns(pair ? ContactShape::kSphere : shape, finite, u.data());
  if (pair) h.second = ShapeFromUnknowns(ContactShape::kSphere, false, u.data() + kSphereUnknowns);
  if (shear) {
    h.first.shear_x_N = u[u.size() - 2];
    h.first.shear_y_N = u[u.size() - 1];
  }
  return h;
}

}  // namespace sedbridge::contact
