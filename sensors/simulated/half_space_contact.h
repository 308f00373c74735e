#pragma once
// Frictionless contact of rigid objects with an elastic half-space, on a square grid of
// cells carrying uniform pressure (Boussinesq; the cell's influence is Love's closed form
// for a uniformly loaded rectangle, Johnson "Contact Mechanics" §3.9). It gives Hertz's
// patch for a sphere and the right pressure for shapes no closed form covers (edges, box
// corners, two objects at once): the simulated pad's `model: halfspace`
// (sensors/simulated/simulated_sensor.h), the contact law the calibration rig's presses fit
// (docs/bridge-fidelity.md §1).
//
// Conditions per cell i, with d_i how far the object lies below the undeformed surface and
// u = K p the surface's deflection: p_i >= 0, u_i >= d_i (the surface stays out of the
// object), and p_i (u_i - d_i) = 0. Only cells with d_i > 0 can press (u >= 0 everywhere
// under a compressive load); the active cells come from block principal pivoting with a
// Cholesky solve of their block, warm-started from the last call's.

#include <vector>

namespace sedbridge::sensors {

class HalfSpaceContact {
 public:
  /// @param cell_m             cell side [m]
  /// @param contact_modulus_Pa E* = E / (1 - nu^2) of the half-space
  HalfSpaceContact(double cell_m, double contact_modulus_Pa);

  /// Surface deflection at a cell centre (di, dj) cells away from a cell under unit
  /// pressure [m / Pa].
  double Influence(int di, int dj) const;

  /// Pressures [Pa] of an n x n grid (row-major, cell (i, j) at i * n + j) from the
  /// penetrations [m] (<= 0: the object is clear of that cell). Returns false (pressures
  /// zero) when the active-set iteration did not settle; counted by failures().
  bool Solve(int n, const std::vector<double>& penetration_m, std::vector<double>* pressure_Pa);

  int failures() const { return failures_; }

 private:
  double cell_m_, contact_modulus_Pa_;
  std::vector<double> table_;  // Influence(i, j) for 0 <= i, j < table_n_, row-major
  int table_n_ = 0;
  std::vector<char> last_active_;  // warm start (cells of the last grid)
  int last_n_ = 0;
  int failures_ = 0;
};

}  // namespace sedbridge::sensors
