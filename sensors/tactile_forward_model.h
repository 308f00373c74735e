#pragma once
// The follower sensor as a forward model: a rigid object pressed into the sensor's elastomer
// pad -> the three-axis reading of every taxel. Used by contact reconstruction (which inverts
// it), by the simulated sensor (`pad: {model: kernel}`), and by `sedbridge fit-sensor`, which
// calibrates its parameters to indentation-stage presses (config/sensors/rig_uskin_4x4/).
//
// Two stages, both linear in the load once the contact patch is known:
//  1. Contact pressure on the pad surface (pad frame, z = 0), on a grid of spacing h:
//       sphere   Hertz:  a = cbrt(3 F R / (4 E*)),  p ~ sqrt(1 - r^2/a^2)
//       cylinder Hertz line contact of the rod's length inside the pad (L):
//                b = sqrt(4 (F/L) R / (pi E*)),  p ~ sqrt(1 - s^2/b^2); a finite rod (an
//                edge of length_mm: a ruler's, a key's) loads only its own length; the
//                band is widened to sqrt(b^2 + w^2), w = rod_min_halfwidth_mm (the sensor's
//                cover spreads a thin line over a width of its own)
//       punch    a rigid rectangular flat face, loaded most at its edges
//                (sensors/flat_punch_pressure.h: SplatFlatPunch)
//       round punch  a rigid round flat face, radius a: p ~ 1 / sqrt(1 - r^2/a^2) (the
//                same file, the same capped edge)
//       corner   a box corner pointing into the pad as the cone of its section area:
//                p ~ arccosh(a / r), a = sqrt(2 F / (pi E* tan beta)) (sensors/cone_pressure.h),
//                widened as the rod's band (the cover spreads a point as a line)
//       flat     uniform over the pad square (side pad_size_mm)
//     each scaled so the cells sum to the normal force F; a tangential force T (stroking)
//     is spread over the same cells in proportion to p.
//  2. Each surface load reaches every taxel through radial kernels of the in-plane offset
//     d = taxel point - load point (rho = |d|, e = d / rho), averaged over the taxel's
//     sensing area (3 x 3 points):
//       normal P:      z += P Kn(rho),         xy += P Kr(rho) e       (outward spread)
//       tangential T:  xy += Kt(rho) T + Kc(rho) e (e . T),  z += Kl(rho) (e . T)
//     with Kn, Kt = A / (1 + (rho/s)^2)^q and Kr, Kl = A (rho/s) / (1 + (rho/s)^2)^q,
//     Kc = A (rho/s)^2 / (1 + (rho/s)^2)^q (the Cerruti-like cross term).
// The kernels are what a real sensor's elastomer does: part of the load never reaches the
// taxels (sum of z readings < F), neighbours see a load between them, and the shear channels
// respond to a purely normal press. Readings are per-taxel forces [N], as the uSkin profile
// calibrates them (pressure x taxel area for Pa profiles).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "sensors/contact_primitive.h"
#include "sensors/sensor_profile.h"
#include "sensors/tactile_model_params.h"

namespace sedbridge::sensors {

/// One offset of the forward model's kernel table: what a unit load on a cell gives a taxel
/// at that offset (taxel-area averaged), one 64-byte cache line.
enum KernelValue { kNormalX, kNormalY, kNormalZ, kTxX, kTxY, kTxZ, kTyY, kTyZ, kKernelValues };
struct alignas(64) KernelEntry {
  double v[kKernelValues] = {};
};

/// Surface load on one grid cell.
struct SurfaceLoad {
  int cell = 0;      ///< index into the model's load grid
  double normal_N = 0;   ///< pressing force on the cell [N]
  double shear_x_N = 0;  ///< tangential force on the cell [N], pad frame
  double shear_y_N = 0;
};

class TactileForwardModel {
 public:
  /// @param taxels  taxel centres [mm] (profile.taxels)
  /// @param taxel_width_mm/height_mm  sensing area of one taxel
  /// @param params  model parameters (kernels precomputed here: a few ms)
  TactileForwardModel(std::vector<TaxelPosition> taxels, double taxel_width_mm, double taxel_height_mm,
                      const TactileModelParams& params);
  /// From a 3-axis profile; throws std::invalid_argument for a normal-only profile.
  TactileForwardModel(const SensorProfile& profile, const TactileModelParams& params);

  int taxel_count() const { return static_cast<int>(taxels_.size()); }
  const TactileModelParams& params() const { return params_; }

  /// Readings [N] of every taxel: out(3 k + a), a = x, y, z. Resized to 3 * #taxels.
  void Predict(const ContactPrimitive& contact, Eigen::VectorXd* readings_N) const;
  /// Predict split by the tangential force, which enters linearly (it spreads over the
  /// patch of the normal force in proportion to the pressure):
  ///   readings = normal_part + shear_x_N * per_shear_x + shear_y_N * per_shear_y  [N, N/N].
  /// Same cost as one Predict; contact.shear_x_N/shear_y_N are ignored. Contact
  /// reconstruction gets the two tangential Jacobian columns from it for free.
  /// patch_cells (optional): cells of the pressure patch, which the cost is proportional to
  /// (0 for the flat's precomputed responses).
  void PredictLinearInShear(const ContactPrimitive& contact, Eigen::VectorXd* normal_part,
                            Eigen::VectorXd* per_shear_x, Eigen::VectorXd* per_shear_y,
                            int* patch_cells = nullptr) const;
  /// The pressure patch on the load grid (cells sum to the normal force and the tangential
  /// force; empty if none).
  void Patch(const ContactPrimitive& contact, std::vector<SurfaceLoad>* loads) const;
  /// Readings [N] for arbitrary surface loads on the grid (the simulated sensor's pad
  /// pressure, for one): out(3 k + a). Resized to 3 * #taxels.
  void Respond(const std::vector<SurfaceLoad>& loads, Eigen::VectorXd* readings_N) const;
  /// About the cells Patch() loads for `contact` (its Hertz patch's area over a cell's,
  /// within the load grid), without computing the patch: what an evaluation will cost, for
  /// budgets. 0 for the flat (precomputed responses) and for no force.
  double PatchCellsEstimate(const ContactPrimitive& contact) const;
  /// Length of a cylinder's axis over the pad square [mm] (a finite rod: of its own length;
  /// 0 for other shapes).
  double RodLengthOnPad_mm(const ContactPrimitive& contact) const;
  /// Load grid: cell_count() cells of cell_size_mm() side; centre of cell i [mm].
  int cell_count() const { return grid_n_ * grid_n_; }
  /// Cells per grid row (cell i is in row i / grid_n(), column i % grid_n(); x along columns).
  int grid_n() const { return grid_n_; }
  double cell_size_mm() const { return params_.grid_mm; }
  Eigen::Vector2d CellCentre_mm(int cell) const;

 private:
  /// Hertz half-widths [mm] of a sphere's patch (radius) and a rod's band (half-width, for
  /// force per length F/L [N/mm]), R clamped to >= 1e-3 mm, widened to about one grid cell
  /// so that every contact covers a few cells and the readings stay smooth in the pose (a
  /// rod's band to at least params.rod_min_halfwidth_mm: the cover's spread).
  double SphereHalfWidth_mm(double force_N, double radius_mm) const;
  double RodHalfWidth_mm(double force_per_length_N_mm, double radius_mm) const;
  /// A corner's cone (sensors/cone_pressure.h) contact radius at force_N [mm], widened to
  /// sqrt(a^2 + w^2) as a rod's band (w = max(grid_mm, rod_min_halfwidth_mm): the cover's
  /// spread of a sharp contact).
  double CornerRadius_mm(double force_N) const;
  void BuildKernelTable();
  /// Per load, its cell's distance into the kernel table [entries]: the entry for taxel k is
  /// table_[taxel_base_[k] - offset]. Once per patch, not once per (taxel, cell): the
  /// integer division per (taxel, cell) pair was about a tenth of an evaluation.
  void TableOffsets(const std::vector<SurfaceLoad>& loads, std::vector<int>* offsets) const;

  std::vector<TaxelPosition> taxels_;
  double taxel_w_mm_, taxel_h_mm_;
  TactileModelParams params_;
  // Load grid: n x n cells of spacing h, anchored so that taxel 0's centre is a node.
  int grid_n_ = 0;
  double grid_x0_mm_ = 0, grid_y0_mm_ = 0;
  // Taxel-area-averaged kernels tabulated on offsets (i, j) * h, |i|,|j| <= table_half_:
  // One cache line per offset (KernelEntry): normal -> (x, y, z), T_x -> (x, y, z),
  // T_y -> (y, z); T_y -> x is T_x -> y (the cross kernel is symmetric).
  int table_half_ = 0;
  std::vector<KernelEntry> table_;
  // Per taxel, offset index of grid cell 0 and strides (table index = base + i*sx + j*sy).
  std::vector<int> taxel_base_;
  int table_stride_ = 0;
  // A flat's readings are linear in (F, T_x, T_y) with a fixed patch: unit responses.
  Eigen::VectorXd flat_normal_, flat_shear_x_, flat_shear_y_;
};

}  // namespace sedbridge::sensors
