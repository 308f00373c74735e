#pragma once
// Taxel readings -> traction at skin nodes: the interpolation, as one linear map.
//
// For a skin node n whose rest position projects (along the pad normal) to the pad-frame
// point q_n, with s_n = registration.ToSensor(q_n) its point on the sensor pad:
//
//   loaded      n faces the pad (outward normal . z_pad >= min_facing), lies at most
//               max_depth_mm below the pad-frame origin (z_pad >= -max_depth_mm), and s_n
//               is inside the sensor footprint (the bounding box of the taxels' sensing
//               areas, centres +- size/2, in sensor coordinates). Every other node gets 0:
//               zero traction outside the footprint.
//   kernel      g_ni = exp(-|s_n - c_i|^2 / (2 sigma^2)), c_i the taxel centres, sigma =
//               kernel_sigma_mm (default: half the smallest taxel spacing), normalised over
//               the taxels (Shepard): w_ni = g_ni / sum_j g_nj. A uniform reading gives a
//               uniform field; between taxels the field blends smoothly.
//   balance     each taxel's column is scaled so that sum_n a_n W_ni = A_i, with a_n the
//               node's skin area (one third of its triangles: exactly what the consistent
//               load of SurfaceTractionForce integrates) and A_i the taxel's area on the
//               pad. Then for ANY reading sum_n a_n (W p)_n = sum_i A_i p_i: the integrated
//               nodal force equals the measured total force, exactly, per axis.
//
// The same W serves pressure and both shear axes (traction per node, pad frame:
// [W sx, W sy, -W p]; an inward pressure acts along -z_pad). A taxel whose footprint
// reaches no loaded node (sensor larger than the fingertip pad) has an empty column; it is
// listed in `unmapped_taxels` and its force is lost (reported at start-up).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "bridge/pad_registration.h"
#include "common/enum_names.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

/// How the FE turns node tractions into nodal forces, and what the map compensates:
///   consistent  W is applied as it is; SurfaceTractionForce's consistent load
///               f_a = A/12 sum_b (1 + delta_ab) t_b spreads half of each node's load to its
///               neighbours (a smooth-traction discretization);
///   lumped      the map is pre-multiplied by M^-1 D (M the consistent-load matrix, D the node
///               areas) so that the FE's nodal forces become exactly f_n = a_n (W p)_n: the
///               load stays where the taxels put it (as with penalty contact, whose forces
///               act at nodes). Precomputed once (one sparse factorization, one solve per
///               taxel); the applied tractions may oscillate, the nodal forces do not.
///               Force balance holds either way.
enum class NodalLoad { kConsistent, kLumped };
/// "lumped", "consistent" (bridge key traction.nodal_load). Inline: the YAML fuzzer links
/// the config readers without the stages.
inline const config::EnumNames<NodalLoad>& NamesOf(NodalLoad) {
  static const config::EnumNames<NodalLoad> names{{NodalLoad::kLumped, "lumped"}, {NodalLoad::kConsistent, "consistent"}};
  return names;
}

struct TractionFieldOptions {
  double kernel_sigma_mm = 0;  ///< Gaussian width on the sensor pad [mm]; 0 = half the smallest taxel spacing
  double min_facing = 0.5;     ///< smallest outward normal . z_pad of a loaded node [-]
  double max_depth_mm = 6;     ///< nodes with z_pad below -max_depth_mm are not loaded [mm]
  NodalLoad nodal_load = NodalLoad::kLumped;
};

/// Skin nodes as the interpolation sees them (one column / entry per node).
struct SkinNodes {
  Eigen::Matrix3Xd position_pad_mm;  ///< rest positions, pad frame [mm]
  Eigen::Matrix3Xd normal_pad;       ///< outward unit normals, pad frame
  Eigen::VectorXd area_m2;           ///< consistent-load area of each node [m^2]
};

struct TractionWeights {
  /// #nodes x #taxels, row-major: node traction [Pa] = W * taxel value [Pa].
  Eigen::SparseMatrix<double, Eigen::RowMajor> W;
  std::vector<int> loaded_nodes;    ///< entries of SkinNodes with a non-zero row
  std::vector<int> unmapped_taxels; ///< taxels whose column is empty
  double sigma_mm = 0;              ///< kernel width used (sensor mm)
  double loaded_area_m2 = 0;        ///< skin area of the loaded nodes
};

/// True if the sensor-pad point lies inside the footprint (taxel sensing areas' bounding box).
bool InsideFootprint(const sensors::SensorProfile& profile, const Eigen::Vector2d& sensor_mm);

/// Builds the force-balanced interpolation map described above.
/// @param[in] profile       taxel centres and size (sensor pad, mm)
/// @param[in] registration  sensor pad -> leader pad frame
/// @param[in] nodes         skin nodes (pad frame)
/// @param[in] options       kernel width, facing and depth limits
TractionWeights BuildTractionWeights(const sensors::SensorProfile& profile, const PadRegistration& registration,
                                     const SkinNodes& nodes, const TractionFieldOptions& options = {});

}  // namespace sedbridge::bridge
