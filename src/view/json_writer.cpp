#include "view/json_writer.h"

#include <cmath>
#include <cstdio>

namespace sedbridge::view {

void JsonWriter::Separate() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
  }
}

void JsonWriter::AppendNumber(double v, int digits) {
  if (!std::isfinite(v)) {
    out_ += "null";
    return;
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  out_ += buf;
}

JsonWriter& JsonWriter::BeginObject() {
  Separate();
  out_ += '{';
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::EndObject() {
  out_ += '}';
  first_.pop_back();
  return *this;
}
JsonWriter& JsonWriter::BeginArray() {
  Separate();
  out_ += '[';
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::EndArray() {
  out_ += ']';
  first_.pop_back();
  return *this;
}
JsonWriter& JsonWriter::Key(const std::string& key) {
  String(key);
  out_ += ':';
  after_key_ = true;
  return *this;
}
JsonWriter& JsonWriter::Number(double v) {
  Separate();
  AppendNumber(v, 9);
  return *this;
}
JsonWriter& JsonWriter::Int(int64_t v) {
  Separate();
  out_ += std::to_string(v);
  return *this;
}
JsonWriter& JsonWriter::Bool(bool v) {
  Separate();
  out_ += v ? "true" : "false";
  return *this;
}
JsonWriter& JsonWriter::Null() {
  Separate();
  out_ += "null";
  return *this;
}
JsonWriter& JsonWriter::String(const std::string& v) {
  Separate();
  out_ += '"';
  for (unsigned char c : v) {
    if (c == '"' || c == '\\') {
      out_ += '\\';
      out_ += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out_ += buf;
    } else {
      out_ += static_cast<char>(c);
    }
  }
  out_ += '"';
  return *this;
}
JsonWriter& JsonWriter::Numbers(const std::vector<double>& v, int digits) {
  BeginArray();
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out_ += ',';
    AppendNumber(v[i], digits);
  }
  first_.back() = v.empty();
  return EndArray();
}
JsonWriter& JsonWriter::Numbers(const std::vector<float>& v, int digits) {
  return Numbers(std::vector<double>(v.begin(), v.end()), digits);
}
JsonWriter& JsonWriter::Ints(const std::vector<int>& v) {
  BeginArray();
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out_ += ',';
    out_ += std::to_string(v[i]);
  }
  return EndArray();
}

}  // namespace sedbridge::view
