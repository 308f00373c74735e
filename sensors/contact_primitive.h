#pragma once
// The contact primitive: one object pressed onto a pad (sphere, rod, flat, flat-faced
// punch, rectangular or round, a box corner), with its pose,
// size and load. The central concept of the contact path: the sensor's forward model
// predicts readings from it, contact reconstruction (src/contact/) recovers it from a scan,
// and the leader press and the simulated pad press its rigid object.
//
// Why here: the lowest layer every user may include (tools/check_include_graph.py). The
// forward model in sensors/ needs it, and sensors/ includes nothing from src/ but
// src/common, which holds no stage's concepts; so the primitive lives in sensors/, in a
// header of its own with nothing of the forward model in it.

#include <string>

#include "common/enum_names.h"

namespace sedbridge::sensors {

/// The contact shapes the model and the reconstruction know.
/// kPunch: a rectangular flat face; kRoundPunch: a round one (sensors/flat_punch_pressure.h);
/// kCorner: a box's corner pointing into the pad (sensors/cone_pressure.h).
enum class ContactShape { kSphere, kCylinder, kFlat, kPunch, kRoundPunch, kCorner };

/// Either flat-faced punch: a rigid face whose pressure keeps its shape as the force grows.
constexpr bool IsPunch(ContactShape s) { return s == ContactShape::kPunch || s == ContactShape::kRoundPunch; }

/// A shape with a radius the fit estimates (sphere, cylinder): not the flat, the punches' faces
/// (their half sizes) or the corner (its angle is the box's).
constexpr bool HasFittedRadius(ContactShape s) { return s == ContactShape::kSphere || s == ContactShape::kCylinder; }

/// "sphere", "cylinder", "flat", "punch", "round_punch", "corner": the one name table (common/enum_names.h).
const config::EnumNames<ContactShape>& NamesOf(ContactShape);
/// "sphere" | "cylinder" | "flat" | "punch" | "round_punch" | "corner"; throws std::invalid_argument for anything else.
ContactShape ContactShapeFromName(const std::string& name);
const char* ContactShapeName(ContactShape shape);

/// One object pressed onto the sensor pad, in the pad frame.
struct ContactPrimitive {
  ContactShape shape = ContactShape::kSphere;
  double x_mm = 0;        ///< sphere: lowest point; cylinder: a point on the axis (a finite rod: its centre); punch (either): its face's centre; corner: its tip; flat: unused
  double y_mm = 0;
  double radius_mm = 5;   ///< sphere/cylinder radius; a round punch's face radius
  double yaw_deg = 0;     ///< cylinder axis direction (cos yaw, sin yaw, 0); a punch's first side; a corner's turn about the vertical (not fitted)
  double length_mm = 0;   ///< cylinder: its length, centred on (x, y) [mm]; 0 = crosses the whole pad
  double normal_force_N = 0;  ///< pressing force (>= 0)
  double shear_x_N = 0;   ///< total tangential force on the pad (object drags the pad along +x)
  double shear_y_N = 0;
  /// Punch: a rectangular face's half sizes along (cos yaw, sin yaw) and across it [mm]
  /// (sensors/flat_punch_pressure.h); radius_mm unused.
  double half_size_mm[2] = {0, 0};
};

}  // namespace sedbridge::sensors
