#pragma once
// Lists the keys a config struct's Serialize names, as dotted paths ("dynamics.dt_s",
// "bone.stiffness_N_m"): the schema as data, for the tests that hold config/*/README.md to
// it. Needs no YAML.

#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/name_value.h"

namespace sedbridge::config {

class SchemaKeysArchive {
 public:
  template <typename T>
  void Visit(const NameValue<T>& field);

  template <typename Visitor>
  void Section(const char* name, Visitor&& visit) {
    const std::string outer = prefix_;
    prefix_ += std::string(name) + ".";
    visit(this);
    prefix_ = outer;
  }

  void HandRead(const char* name) { keys_.push_back(prefix_ + name); }

  const std::vector<std::string>& keys() const { return keys_; }

 private:
  template <typename T, typename = void>
  struct HasSerialize : std::false_type {};
  template <typename T>
  struct HasSerialize<T, std::void_t<decltype(std::declval<T&>().Serialize(std::declval<SchemaKeysArchive*>()))>>
      : std::true_type {};
  template <typename T>
  struct Unwrap {
    using type = T;
  };
  template <typename U>
  struct Unwrap<std::optional<U>> {
    using type = U;
  };

  std::string prefix_;
  std::vector<std::string> keys_;
};

template <typename T>
void SchemaKeysArchive::Visit(const NameValue<T>& field) {
  using Value = typename Unwrap<T>::type;
  if constexpr (HasSerialize<Value>::value) {
    Section(field.name, [](SchemaKeysArchive* a) {
      Value v{};
      v.Serialize(a);
    });
  } else {
    keys_.push_back(prefix_ + field.name);
  }
}

/// Every key `T::Serialize` names, dotted, in visit order.
template <typename T>
std::vector<std::string> SchemaKeys() {
  T s{};
  SchemaKeysArchive archive;
  s.Serialize(&archive);
  return archive.keys();
}

}  // namespace sedbridge::config
