#pragma once
// One field of a config schema: its YAML key, the member it fills, its unit and the range
// of values it may take. A config struct names every field once, in
//
//   template <typename Archive>
//   void Serialize(Archive* a) {
//     a->Visit(Field("dt_s", &dt_s).Unit("s").Positive());
//     a->Visit(Field("steps", &steps).InRange(1, kMaxSceneSteps));
//     a->Section("solver", [&](auto* s) { s->Visit(Field("type", &solver).OneOf(SolverNames())); });
//   }
//
// A key whose value is no plain field (a trajectory, a list of objects) is named with
// `a->HandRead("motion")` and read by the owner's parser after the archive.
//
// Every archive (common/yaml_read_archive.h reads YAML, common/schema_keys.h lists the
// keys) walks the same list. The default of a field is its member initialiser: a reader
// leaves a member whose key is absent as it is. This header needs no YAML (Drake's
// common/name_value.h is the model).

#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace sedbridge::config {

/// The values a number may take: [min, max], each end closed or open. Default: any value.
struct ValueRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  ///< true: min itself is not allowed
  bool max_open = false;

  bool Contains(double x) const {
    return (min_open ? x > min : x >= min) && (max_open ? x < max : x <= max);
  }
  bool bounded_below() const { return min > -std::numeric_limits<double>::infinity(); }
  bool bounded_above() const { return max < std::numeric_limits<double>::infinity(); }

  /// "> 0", ">= 0", "<= 1" or "in (0, 10] kPa" (with `unit` after an interval).
  std::string Describe(const std::string& unit) const {
    std::ostringstream s;
    if (bounded_below() && bounded_above()) {
      s << "in " << (min_open ? "(" : "[") << min << ", " << max << (max_open ? ")" : "]");
      if (!unit.empty()) s << " " << unit;
    } else if (bounded_below()) {
      s << (min_open ? "> " : ">= ") << min;
    } else if (bounded_above()) {
      s << (max_open ? "< " : "<= ") << max;
    }
    return s.str();
  }
};

/// A field: `name` is the YAML key, `value` the member. Built by Field() and chained setters.
template <typename T>
struct NameValue {
  const char* name = nullptr;
  T* value = nullptr;
  const char* unit = "";     ///< for messages and docs ("" = none or in the key's name)
  ValueRange range;          ///< numbers (and each number of a sequence)
  bool required = false;     ///< absent key is an error (else the member keeps its default)
  /// Strings only: the allowed names (empty = any string). Give the list from the one
  /// function that owns it (e.g. scene::PresetNames()).
  std::vector<std::string> choices;
  /// The file gives the value in other units: member = file value * scale (e.g. a key in mm
  /// for a member in m: 1e-3). Ranges apply to the file value.
  double scale = 1.0;

  NameValue& Unit(const char* u) { unit = u; return *this; }
  NameValue& Required() { required = true; return *this; }
  NameValue& Positive() { range.min = 0; range.min_open = true; return *this; }
  NameValue& NonNegative() { range.min = 0; range.min_open = false; return *this; }
  NameValue& AtLeast(double lo) { range.min = lo; range.min_open = false; return *this; }
  NameValue& Below(double hi) { range.max = hi; range.max_open = true; return *this; }
  /// Closed interval [lo, hi].
  NameValue& InRange(double lo, double hi) { range = {lo, hi, false, false}; return *this; }
  /// Any interval (open or closed at either end).
  NameValue& Within(ValueRange r) { range = r; return *this; }
  NameValue& OneOf(std::vector<std::string> names) { choices = std::move(names); return *this; }
  NameValue& Scale(double file_to_member) { scale = file_to_member; return *this; }
};

/// Names a member: `a->Visit(Field("dt_s", &dt_s).Positive())`.
template <typename T>
NameValue<T> Field(const char* name, T* value) {
  NameValue<T> field;
  field.name = name;
  field.value = value;
  return field;
}

}  // namespace sedbridge::config
