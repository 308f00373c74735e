#pragma once
// Rigid shapes as signed distance fields (SDF), shared by FE penalty contact and the
// simulated follower sensor. Convention: distance > 0 outside the object, < 0 inside;
// `normal` is the unit gradient (outward from the object). Object frame, SI units.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace sedbridge::geometry {

struct SdfSample {
  double distance_m = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, outward
};

class SignedDistanceField {
 public:
  virtual ~SignedDistanceField() = default;
  /// Distance and outward normal at `p_m` (object frame, metres).
  virtual SdfSample Evaluate(const Eigen::Vector3d& p_m) const = 0;
  virtual std::string Describe() const = 0;
  /// True when the distance is 1-Lipschitz, |d(p) - d(q)| <= |p - q|: a contact solve may
  /// then skip points it knows to be far from the surface (plane, sphere, cylinder).
  virtual bool lipschitz() const { return false; }
};

/// Half-space z < 0 of the object frame (surface z = 0, normal +z).
class PlaneSdf final : public SignedDistanceField {
 public:
  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override { return "plane"; }
  bool lipschitz() const override { return true; }
};

class SphereSdf final : public SignedDistanceField {
 public:
  explicit SphereSdf(double radius_m);
  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override;
  bool lipschitz() const override { return true; }

 private:
  double radius_m_;
};

/// Cylinder along the object x axis; `half_length_m` <= 0 means infinite. A thin
/// cylinder is the "edge" indenter.
class CylinderSdf final : public SignedDistanceField {
 public:
  CylinderSdf(double radius_m, double half_length_m);
  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override;
  bool lipschitz() const override { return true; }

 private:
  double radius_m_, half_length_m_;
};

/// A plate with round holes through it (a suction display's surface): the half-space z < 0
/// of the object frame (surface z = 0, normal +z, as PlaneSdf) less infinite cylinders along
/// z of radius `hole_radius_m` at `hole_centres_m` (x, y; holes must not overlap). Distance
/// max(z, -(distance to the nearest hole's wall)): exact inside the solid, above the plate
/// clear of the holes and inside a hole below the surface; a lower bound above a hole
/// (the rim is nearer than either face). 1-Lipschitz (a max of 1-Lipschitz functions).
class PlateWithHolesSdf final : public SignedDistanceField {
 public:
  PlateWithHolesSdf(std::vector<Eigen::Vector2d> hole_centres_m, double hole_radius_m);
  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override;
  bool lipschitz() const override { return true; }

 private:
  std::vector<Eigen::Vector2d> centres_m_;
  double radius_m_;
};

/// Axis-aligned box centred at the origin with edges rounded by `rounding_m`
/// (0 = sharp; the sharp case still has a well-defined outward normal everywhere).
class BoxSdf final : public SignedDistanceField {
 public:
  BoxSdf(const Eigen::Vector3d& half_extents_m, double rounding_m);
  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override;

 private:
  Eigen::Vector3d half_extents_m_;
  double rounding_m_;
};

/// Square-wave grating: ridges parallel to y, repeating along x with `period_m`, each
/// `ridge_width_m` wide, tops at z = 0, grooves `depth_m` deep (floor at z = -depth).
class GratingSdf final : public SignedDistanceField {
 public:
  GratingSdf(double period_m, double ridge_width_m, double depth_m);
  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override;

 private:
  double period_m_, ridge_width_m_, depth_m_;
};

/// Sampled SDF on a regular grid, trilinear interpolation; outside the grid the
/// distance is extended with the distance to the grid box.
class GridSdf final : public SignedDistanceField {
 public:
  /// `values_m` ordered x fastest: index = i + nx * (j + ny * k).
  GridSdf(Eigen::Vector3i counts, Eigen::Vector3d origin_m, double spacing_m,
          std::vector<double> values_m);
  /// Samples `field` on the grid (used for tests and to bake analytic shapes).
  static GridSdf Sample(const SignedDistanceField& field, Eigen::Vector3i counts,
                        Eigen::Vector3d origin_m, double spacing_m);
  /// Text file: "nx ny nz", "origin_x origin_y origin_z spacing" (metres), then
  /// nx*ny*nz distances (metres, x fastest). Throws config::ConfigError with line.
  static GridSdf Load(const std::string& path);

  SdfSample Evaluate(const Eigen::Vector3d& p_m) const override;
  std::string Describe() const override;

 private:
  double Value(int i, int j, int k) const;
  Eigen::Vector3i counts_;
  Eigen::Vector3d origin_m_;
  double spacing_m_;
  std::vector<double> values_m_;
};

}  // namespace sedbridge::geometry
