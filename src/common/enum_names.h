#pragma once
// One name table per config enum, and the string <-> enum functions every reader and writer
// uses, so an enum's names are spelled and checked in one place. An enum opts in with one
// function found by argument-dependent lookup, next to the enum:
//
//   enum class NodalLoad { kLumped, kConsistent };
//   inline const config::EnumNames<NodalLoad>& NamesOf(NodalLoad) {
//     static const config::EnumNames<NodalLoad> names{{NodalLoad::kLumped, "lumped"},
//                                                     {NodalLoad::kConsistent, "consistent"}};
//     return names;
//   }
//
// Then NameOf(NodalLoad::kLumped) == "lumped", EnumFromName<NodalLoad>("consistent"), and
// a config field of that type reads and checks its name.

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sedbridge::config {

/// (value, name) pairs in the order they are listed to users.
template <typename E>
using EnumNames = std::vector<std::pair<E, const char*>>;

/// True for an enum that has a NamesOf(E) table.
template <typename E, typename = void>
struct HasEnumNames : std::false_type {};
template <typename E>
struct HasEnumNames<E, std::void_t<decltype(NamesOf(E{}))>> : std::true_type {};

/// The name of `value` ("?" for a value outside the table), as the table's static string
/// (for ToString functions that return const char*).
template <typename E>
const char* NameCStrOf(E value) {
  for (const auto& [v, name] : NamesOf(E{}))
    if (v == value) return name;
  return "?";
}

/// The name of `value` ("?" for a value outside the table).
template <typename E>
std::string NameOf(E value) {
  return NameCStrOf(value);
}

/// The value named `name`, nullopt if none is.
template <typename E>
std::optional<E> EnumFromName(const std::string& name) {
  for (const auto& [v, n] : NamesOf(E{}))
    if (name == n) return v;
  return std::nullopt;
}

/// Every name, in table order.
template <typename E>
std::vector<std::string> AllNames() {
  std::vector<std::string> out;
  for (const auto& entry : NamesOf(E{})) out.push_back(entry.second);
  return out;
}

/// "a, b, c": the list error messages show.
inline std::string JoinNames(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

/// The value named `name`; throws std::invalid_argument "unknown <what> 'x' (a, b, c)".
template <typename E>
E ParseEnum(const std::string& name, const std::string& what) {
  if (auto v = EnumFromName<E>(name)) return *v;
  throw std::invalid_argument("unknown " + what + " '" + name + "' (" + JoinNames(AllNames<E>()) + ")");
}

}  // namespace sedbridge::config
