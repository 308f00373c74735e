#pragma once
// Reads a config struct from YAML through its Serialize(Archive*) (common/name_value.h):
// strict like MapReader, which it is built on: every error names file:line:column, a key
// nobody visited is an error (MapReader::Finish), a repeated key is an error at load time,
// and each number is checked against the range declared beside its field.
//
//   MapReader r(doc.root, doc.file);
//   SceneDescription s;
//   ReadYaml(r, &s);   // visits every field, then r.Finish()
//
// Include this in .cpp files only: stage headers declare Serialize and stay free of YAML.

#include <array>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/enum_names.h"
#include "common/name_value.h"
#include "common/yaml_reader.h"

namespace sedbridge::config {

class YamlReadArchive;

namespace internal {
template <typename T, typename = void>
struct HasSerialize : std::false_type {};
template <typename T>
struct HasSerialize<T, std::void_t<decltype(std::declval<T&>().Serialize(std::declval<YamlReadArchive*>()))>>
    : std::true_type {};
template <typename T>
struct IsOptional : std::false_type {};
template <typename U>
struct IsOptional<std::optional<U>> : std::true_type {};
template <typename T>
struct IsVector : std::false_type {};
template <typename U, typename A>
struct IsVector<std::vector<U, A>> : std::true_type {};
/// Entries of a fixed-size vector of numbers (Eigen::Vector2d, std::array): [x, y] in
/// YAML. 0 for any other type.
template <typename T, typename = void>
struct FixedSize : std::integral_constant<std::size_t, 0> {};
template <typename T>
struct FixedSize<T, std::enable_if_t<(T::SizeAtCompileTime > 0)>>
    : std::integral_constant<std::size_t, std::size_t(T::SizeAtCompileTime)> {};
template <typename T, std::size_t N>
struct FixedSize<std::array<T, N>> : std::integral_constant<std::size_t, N> {};
}  // namespace internal

/// Archive that reads fields from one YAML mapping (see the file comment).
class YamlReadArchive {
 public:
  explicit YamlReadArchive(MapReader* reader) : reader_(reader) {}

  /// Reads one field if its key is present (required fields: must be present).
  template <typename T>
  void Visit(const NameValue<T>& field);

  /// A nested mapping `name:` whose keys fill members of this same struct (a YAML section
  /// that groups flat members). `visit(YamlReadArchive*)` names its fields. Absent: skipped.
  template <typename Visitor>
  void Section(const char* name, Visitor&& visit);

  /// A key the owner reads itself after the archive (a trajectory, a list of objects):
  /// named in the schema and accepted here, not read.
  void HandRead(const char* name) {
    if (reader_->Has(name)) reader_->Node(name);
  }

  MapReader& reader() { return *reader_; }

 private:
  template <typename T, typename U>
  void ReadNode(const YAML::Node& node, const NameValue<U>& field, T* out);
  template <typename U>
  void CheckRange(const YAML::Node& node, const NameValue<U>& field, double x);

  MapReader* reader_;
};

/// Reads every field of `s` (s->Serialize) from `reader`, then rejects unknown keys.
template <typename T>
void ReadYaml(MapReader& reader, T* s) {
  YamlReadArchive archive(&reader);
  s->Serialize(&archive);
  reader.Finish();
}

// ---- template implementations ----

template <typename T>
void YamlReadArchive::Visit(const NameValue<T>& field) {
  const std::string key = field.name;
  if (!reader_->Has(key)) {
    if (field.required) reader_->Fail("missing required key '" + key + "'");
    return;
  }
  ReadNode(reader_->Node(key), field, field.value);
}

template <typename Visitor>
void YamlReadArchive::Section(const char* name, Visitor&& visit) {
  if (!reader_->Has(name)) return;
  MapReader child = reader_->Child(name);
  YamlReadArchive sub(&child);
  visit(&sub);
  child.Finish();
}

template <typename U>
void YamlReadArchive::CheckRange(const YAML::Node& node, const NameValue<U>& field, double x) {
  if (field.range.Contains(x)) return;
  std::ostringstream m;
  m << "'" << field.name << "' must be " << field.range.Describe(field.unit) << " (got " << x << ")";
  reader_->Fail(node, m.str());
}

template <typename T, typename U>
void YamlReadArchive::ReadNode(const YAML::Node& node, const NameValue<U>& field, T* out) {
  const std::string key = field.name;
  const std::string& file = reader_->file();
  if constexpr (internal::IsOptional<T>::value) {
    typename T::value_type v = out->has_value() ? **out : typename T::value_type{};
    ReadNode(node, field, &v);
    *out = std::move(v);
  } else if constexpr (internal::HasSerialize<T>::value) {
    MapReader child(node, file);
    ReadYaml(child, out);
  } else if constexpr (std::is_enum_v<T>) {
    static_assert(HasEnumNames<T>::value, "a config enum needs a NamesOf(E) table (common/enum_names.h)");
    const std::string name = As<std::string>(node, file, key);
    const auto v = EnumFromName<T>(name);
    if (!v) reader_->Fail(node, "'" + key + "' must be one of: " + JoinNames(AllNames<T>()) + " (got '" + name + "')");
    *out = *v;
  } else if constexpr (std::is_same_v<T, std::string>) {
    *out = As<std::string>(node, file, key);
    if (!field.choices.empty()) {
      bool known = false;
      for (const auto& c : field.choices) known = known || c == *out;
      if (!known)
        reader_->Fail(node, "'" + key + "' must be one of: " + JoinNames(field.choices) + " (got '" + *out + "')");
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    *out = As<bool>(node, file, key);
  } else if constexpr (std::is_arithmetic_v<T>) {
    const T x = As<T>(node, file, key);
    CheckRange(node, field, static_cast<double>(x));
    if constexpr (std::is_floating_point_v<T>) *out = x * static_cast<T>(field.scale);
    else *out = x;
  } else if constexpr (internal::IsVector<T>::value) {
    if (!node.IsSequence()) reader_->Fail(node, "'" + key + "' must be a list");
    T values;
    for (std::size_t i = 0; i < node.size(); ++i) {
      typename T::value_type v{};
      ReadNode(node[i], field, &v);
      values.push_back(std::move(v));
    }
    *out = std::move(values);
  } else if constexpr (internal::FixedSize<T>::value > 0) {
    constexpr std::size_t n = internal::FixedSize<T>::value;
    if (!node.IsSequence() || node.size() != n)
      reader_->Fail(node, "'" + key + "' must be a list of " + std::to_string(n) + " numbers");
    for (std::size_t i = 0; i < n; ++i) ReadNode(node[i], field, &(*out)[i]);
  } else {
    static_assert(sizeof(T) == 0, "YamlReadArchive: no reader for this field type");
  }
}

}  // namespace sedbridge::config
