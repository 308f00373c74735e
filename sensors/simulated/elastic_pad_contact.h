#pragma once
// Frictionless contact of rigid objects with an elastic pad — a half-space, or a layer of
// it on a rigid base — on a square grid of cells carrying uniform pressure (Boussinesq; the
// cell's influence is Love's closed form for a uniformly loaded rectangle, Johnson "Contact
// Mechanics" §3.9). The half-space gives Hertz's patch for a sphere and the right pressure
// for shapes no closed form covers (edges, box corners, two objects at once): the simulated
// pad's `model: halfspace` (sensors/simulated/simulated_sensor.h); the layer is `model:
// layer`, the pad that reproduces the calibration rig's presses best
// (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s1).
//
// A layer: the same elastomer as a layer of thickness h bonded to a rigid base (a real
// sensor's skin over its circuit board). Its surface deflection under a pressure of
// transform P(k) is P(k) 2 / (E* k) C(kh), with (Johnson-style layer solution, frictionless
// surface, bonded base; e.g. Li & Chou 1997)
//   C(t) = [(3 - 4 nu) sinh 2t - 2t] / [(3 - 4 nu) cosh 2t + 2 t^2 + 5 - 12 nu + 8 nu^2]:
// C -> 1 for contacts much smaller than h (the half-space: Hertz), and C -> t (1 - 2 nu) /
// (2 (1 - nu)^2) for contacts much wider (each point compressed like a confined column,
// w = p h / E_oed: Winkler's foundation). A cell's influence is Love's plus the layer's
// correction, a Hankel transform of (C - 1) for a disk of the cell's area (the correction is
// smooth on the scale of h, so the disk stands in for the square), tabulated along r.
//
// Conditions per cell i, with d_i how far the object lies below the undeformed surface and
// u = K p the surface's deflection: p_i >= 0, u_i >= d_i (the surface stays out of the
// object), and p_i (u_i - d_i) = 0. Only cells with d_i > 0 can press (u >= 0 everywhere
// under a compressive load); the active cells come from block principal pivoting with a
// Cholesky solve of their block, warm-started from the last call's.

#include <vector>

namespace sedbridge::sensors {

/// A finite elastic layer on a rigid base (thickness_m = 0: the half-space).
struct ElasticLayer {
  double thickness_m = 0;      ///< h [m]; 0 = infinitely thick
  double poisson_ratio = 0.5;  ///< nu in [0, 0.5]; matters only for a finite layer
};

/// Surface deflection [m] of an elastic layer (E* = contact_modulus_Pa) at distance r_m from
/// the centre of a disk of radius disk_m under unit pressure [Pa], minus the half-space's:
/// the layer's correction, by a Hankel transform of C(kh) - 1 (header comment).
double LayerCorrection_m_per_Pa(double r_m, double disk_m, double contact_modulus_Pa, const ElasticLayer& layer);

class ElasticPadContact {
 public:
  /// @param cell_m             cell side [m]
  /// @param contact_modulus_Pa E* = E / (1 - nu^2) of the elastomer
  /// @param layer              its thickness on a rigid base (default: a half-space)
  ElasticPadContact(double cell_m, double contact_modulus_Pa, ElasticLayer layer = {});

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
  // A finite layer: its correction to Love's influence at r = k * correction_step_m_
  // (linear between), and zero influence beyond the last entry (the layer's reach).
  std::vector<double> correction_;
  double correction_step_m_ = 0;
  std::vector<double> table_;  // Influence(i, j) for 0 <= i, j < table_n_, row-major
  int table_n_ = 0;
  std::vector<char> last_active_;  // warm start (cells of the last grid)
  int last_n_ = 0;
  int failures_ = 0;
};

}  // namespace sedbridge::sensors
