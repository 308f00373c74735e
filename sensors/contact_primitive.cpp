#include "sensors/contact_primitive.h"

namespace sedbridge::sensors {

const config::EnumNames<ContactShape>& NamesOf(ContactShape) {
  static const config::EnumNames<ContactShape> names{
      {ContactShape::kSphere, "sphere"}, {ContactShape::kCylinder, "cylinder"}, {ContactShape::kFlat, "flat"},
      {ContactShape::kPunch, "punch"}, {ContactShape::kRoundPunch, "round_punch"},
      {ContactShape::kCorner, "corner"}};
  return names;
}

ContactShape ContactShapeFromName(const std::string& name) { return config::ParseEnum<ContactShape>(name, "contact shape"); }

const char* ContactShapeName(ContactShape shape) { return config::NameCStrOf(shape); }

}  // namespace sedbridge::sensors
