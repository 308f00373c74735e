#include "common/geometry/signed_distance_field.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include "common/config_error.h"

namespace sedbridge::geometry {
namespace {

std::string Mm(double m) {
  std::ostringstream os;
  os << m * 1e3 << " mm";
  return os.str();
}

Eigen::Vector3d SafeNormalize(const Eigen::Vector3d& v, const Eigen::Vector3d& fallback) {
  const double n = v.norm();
  return n > 1e-15 ? Eigen::Vector3d(v / n) : fallback;
}

}  // namespace

SdfSample PlaneSdf::Evaluate(const Eigen::Vector3d& p) const {
  return {p.z(), Eigen::Vector3d::UnitZ()};
}

SphereSdf::SphereSdf(double radius_m) : radius_m_(radius_m) {}

SdfSample SphereSdf::Evaluate(const Eigen::Vector3d& p) const {
  return {p.norm() - radius_m_, SafeNormalize(p, Eigen::Vector3d::UnitZ())};
}

std::string SphereSdf::Describe() const { return "sphere r=" + Mm(radius_m_); }

CylinderSdf::CylinderSdf(double radius_m, double half_length_m)
    : radius_m_(radius_m), half_length_m_(half_length_m) {}

SdfSample CylinderSdf::Evaluate(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d radial(0, p.y(), p.z());
  const double dr = radial.norm() - radius_m_;
  const Eigen::Vector3d n_r = SafeNormalize(radial, Eigen::Vector3d::UnitZ());
  if (half_length_m_ <= 0) return {dr, n_r};
  const double dx = std::abs(p.x()) - half_length_m_;
  const Eigen::Vector3d n_x(p.x() >= 0 ? 1.0 : -1.0, 0, 0);
  if (dr > 0 && dx > 0) {
    const Eigen::Vector3d g = dr * n_r + dx * n_x;
    return {std::hypot(dr, dx), SafeNormalize(g, n_r)};
  }
  return dr > dx ? SdfSample{dr, n_r} : SdfSample{dx, n_x};
}

std::string CylinderSdf::Describe() const {
  return "cylinder r=" + Mm(radius_m_) +
         (half_length_m_ > 0 ? " length=" + Mm(2 * half_length_m_) : " infinite");
}

PlateWithHolesSdf::PlateWithHolesSdf(std::vector<Eigen::Vector2d> hole_centres_m, double hole_radius_m)
    : centres_m_(std::move(hole_centres_m)), radius_m_(hole_radius_m) {}

SdfSample PlateWithHolesSdf::Evaluate(const Eigen::Vector3d& p) const {
  // The nearest hole's wall: signed distance (< 0 inside the hole) and the radial direction.
  double wall = std::numeric_limits<double>::infinity();
  Eigen::Vector3d radial = Eigen::Vector3d::UnitX();
  for (const Eigen::Vector2d& c : centres_m_) {
    const Eigen::Vector3d d(p.x() - c.x(), p.y() - c.y(), 0.0);
    const double to_wall = d.norm() - radius_m_;
    if (to_wall < wall) wall = to_wall, radial = d;
  }
  if (p.z() >= -wall) return {p.z(), Eigen::Vector3d::UnitZ()};
  // The wall is the nearer face: the solid's outward normal points into the hole.
  return {-wall, -SafeNormalize(radial, Eigen::Vector3d::UnitX())};
}

std::string PlateWithHolesSdf::Describe() const {
  return "plate with " + std::to_string(centres_m_.size()) + " holes r=" + Mm(radius_m_);
}

BoxSdf::BoxSdf(const Eigen::Vector3d& half_extents_m, double rounding_m)
    : half_extents_m_(half_extents_m), rounding_m_(rounding_m) {}

SdfSample BoxSdf::Evaluate(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d inner = (half_extents_m_.array() - rounding_m_).max(0.0).matrix();
  const Eigen::Vector3d sign = p.unaryExpr([](double v) { return v >= 0 ? 1.0 : -1.0; });
  const Eigen::Vector3d q = p.cwiseAbs() - inner;
  const Eigen::Vector3d outside = q.cwiseMax(0.0);
  if (outside.squaredNorm() > 0) {
    const double d = outside.norm();
    return {d - rounding_m_, Eigen::Vector3d(sign.cwiseProduct(outside) / d)};
  }
  // Inside the inner box: the nearest face decides.
  Eigen::Index axis;
  const double d = q.maxCoeff(&axis);
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[axis] = sign[axis];
  return {d - rounding_m_, n};
}

std::string BoxSdf::Describe() const {
  return "box " + Mm(2 * half_extents_m_.x()) + " x " + Mm(2 * half_extents_m_.y()) + " x " +
         Mm(2 * half_extents_m_.z());
}

GratingSdf::GratingSdf(double period_m, double ridge_width_m, double depth_m)
    : period_m_(period_m), ridge_width_m_(ridge_width_m), depth_m_(depth_m) {}

SdfSample GratingSdf::Evaluate(const Eigen::Vector3d& p) const {
  // Fold x into one period centred on a ridge; the grating is the union of the ridge
  // (|x| < w/2, -depth < z < 0) and the floor (z < -depth): SDF of a union = min.
  double x = std::fmod(p.x(), period_m_);
  if (x < 0) x += period_m_;
  if (x > 0.5 * period_m_) x -= period_m_;
  const double hw = 0.5 * ridge_width_m_, hd = 0.5 * depth_m_;
  BoxSdf ridge(Eigen::Vector3d(hw, 1e9, hd), 0.0);
  SdfSample s = ridge.Evaluate(Eigen::Vector3d(x, 0.0, p.z() + hd));
  const double floor_d = p.z() + depth_m_;
  if (floor_d < s.distance_m) return {floor_d, Eigen::Vector3d::UnitZ()};
  return s;
}

std::string GratingSdf::Describe() const {
  return "grating period=" + Mm(period_m_) + " ridge=" + Mm(ridge_width_m_) +
         " depth=" + Mm(depth_m_);
}

GridSdf::GridSdf(Eigen::Vector3i counts, Eigen::Vector3d origin_m, double spacing_m,
                 std::vector<double> values_m)
    : counts_(counts), origin_m_(origin_m), spacing_m_(spacing_m), values_m_(std::move(values_m)) {
  if ((counts_.array() < 2).any() || spacing_m_ <= 0 ||
      values_m_.size() != size_t(counts_.prod())) {
    throw config::ConfigError({"<grid sdf>", 0, 0},
                              "grid SDF needs >= 2 samples per axis, spacing > 0 and nx*ny*nz values");
  }
}

GridSdf GridSdf::Sample(const SignedDistanceField& field, Eigen::Vector3i counts,
                        Eigen::Vector3d origin_m, double spacing_m) {
  std::vector<double> v(size_t(counts.prod()));
  for (int k = 0; k < counts.z(); ++k)
    for (int j = 0; j < counts.y(); ++j)
      for (int i = 0; i < counts.x(); ++i)
        v[size_t(i + counts.x() * (j + counts.y() * k))] =
            field.Evaluate(origin_m + spacing_m * Eigen::Vector3d(i, j, k)).distance_m;
  return GridSdf(counts, origin_m, spacing_m, std::move(v));
}

GridSdf GridSdf::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw config::ConfigError({path, 0, 0}, "cannot open grid SDF file");
  Eigen::Vector3i n;
  Eigen::Vector3d o;
  double h;
  if (!(in >> n.x() >> n.y() >> n.z()))
    throw config::ConfigError({path, 1, 0}, "expected 'nx ny nz'");
  if (!(in >> o.x() >> o.y() >> o.z() >> h))
    throw config::ConfigError({path, 2, 0}, "expected 'origin_x origin_y origin_z spacing'");
  if ((n.array() < 2).any() || n.prod() > 100'000'000)
    throw config::ConfigError({path, 1, 0}, "grid counts must be >= 2 and the grid not huge");
  std::vector<double> v(size_t(n.prod()));
  for (size_t i = 0; i < v.size(); ++i) {
    if (!(in >> v[i]) || !std::isfinite(v[i]))
      throw config::ConfigError({path, 0, 0}, "value " + std::to_string(i) +
                                                  " is missing or not finite");
  }
  return GridSdf(n, o, h, std::move(v));
}

double GridSdf::Value(int i, int j, int k) const {
  return values_m_[size_t(i + counts_.x() * (j + counts_.y() * k))];
}

SdfSample GridSdf::Evaluate(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d extent = spacing_m_ * (counts_ - Eigen::Vector3i::Ones()).cast<double>();
  const Eigen::Vector3d clamped = p.cwiseMax(origin_m_).cwiseMin(origin_m_ + extent);
  const double outside = (p - clamped).norm();
  const Eigen::Vector3d g = (clamped - origin_m_) / spacing_m_;
  Eigen::Vector3i c0;
  Eigen::Vector3d f;
  for (int a = 0; a < 3; ++a) {
    c0[a] = std::min(int(std::floor(g[a])), counts_[a] - 2);
    f[a] = g[a] - c0[a];
  }
  double d = 0;
  Eigen::Vector3d grad = Eigen::Vector3d::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
    const double v = Value(c0.x() + dx, c0.y() + dy, c0.z() + dz);
    const double wx = dx ? f.x() : 1 - f.x(), wy = dy ? f.y() : 1 - f.y(),
                 wz = dz ? f.z() : 1 - f.z();
    d += v * wx * wy * wz;
    grad.x() += v * (dx ? 1 : -1) * wy * wz;
    grad.y() += v * wx * (dy ? 1 : -1) * wz;
    grad.z() += v * wx * wy * (dz ? 1 : -1);
  }
  Eigen::Vector3d n = SafeNormalize(grad, Eigen::Vector3d::UnitZ());
  if (outside > 0) n = SafeNormalize(n * std::max(d, 0.0) + (p - clamped), n);
  return {d + outside, n};
}

std::string GridSdf::Describe() const {
  return "grid " + std::to_string(counts_.x()) + "x" + std::to_string(counts_.y()) + "x" +
         std::to_string(counts_.z()) + " spacing " + Mm(spacing_m_);
}

}  // namespace sedbridge::geometry
