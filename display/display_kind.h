#pragma once
// The kind of a haptic distribution display (suction, pin, electrotactile) and the unit its
// commands take. Its own header because both the profile and its device model name it.

#include <string>

#include "common/enum_names.h"

namespace sedbridge::display {

enum class DisplayKind {
  kSuction,         ///< suction-pressure array; unit kPa of suction below ambient
  kPin,             ///< pin array; unit mm of pin height above the rest plane
  kElectrotactile,  ///< electrode array; unit mA of stimulation current
};
/// "suction", "pin", "electrotactile" (key `kind`).
const config::EnumNames<DisplayKind>& NamesOf(DisplayKind);

/// "suction", "pin", "electrotactile" (NameOf(kind)).
std::string ToString(DisplayKind kind);
/// The unit every profile of that kind must use.
std::string UnitOf(DisplayKind kind);

}  // namespace sedbridge::display
