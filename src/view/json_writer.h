#pragma once
// A small append-only JSON writer for the view's messages (frames, mesh, timelines): numbers
// that are not finite become null (JSON has no NaN), strings are escaped. No DOM, no parser:
// the view only writes JSON.

#include <cstdint>
#include <string>
#include <vector>

namespace sedbridge::view {

class JsonWriter {
 public:
  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  /// The key of the next value inside an object.
  JsonWriter& Key(const std::string& key);
  JsonWriter& Number(double v);
  JsonWriter& Int(int64_t v);
  JsonWriter& Bool(bool v);
  JsonWriter& String(const std::string& v);
  JsonWriter& Null();
  /// An array of numbers, written with `digits` significant digits.
  JsonWriter& Numbers(const std::vector<double>& v, int digits = 6);
  JsonWriter& Numbers(const std::vector<float>& v, int digits = 6);
  JsonWriter& Ints(const std::vector<int>& v);

  const std::string& str() const { return out_; }

 private:
  void Separate();
  void AppendNumber(double v, int digits);
  std::string out_;
  std::vector<bool> first_;  ///< per open container: nothing written in it yet
  bool after_key_ = false;
};

}  // namespace sedbridge::view
