#include "display/display_kind.h"

namespace sedbridge::display {

const config::EnumNames<DisplayKind>& NamesOf(DisplayKind) {
  static const config::EnumNames<DisplayKind> names{
      {DisplayKind::kSuction, "suction"}, {DisplayKind::kPin, "pin"}, {DisplayKind::kElectrotactile, "electrotactile"}};
  return names;
}

std::string ToString(DisplayKind kind) { return config::NameOf(kind); }

std::string UnitOf(DisplayKind kind) {
  switch (kind) {
    case DisplayKind::kSuction: return "kPa";
    case DisplayKind::kPin: return "mm";
    case DisplayKind::kElectrotactile: return "mA";
  }
  return "?";
}

}  // namespace sedbridge::display
