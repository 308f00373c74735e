#include "display/lcm_conversions.h"

#include <cmath>
#include <limits>
#include <vector>

namespace sedbridge::display {

float ToLcmFloat(double x) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (x > kMax) return std::numeric_limits<float>::infinity();
  if (x < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(x);  // NaN stays NaN
}

namespace {

std::vector<float> ToFloats(const std::vector<double>& v) {
  std::vector<float> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = ToLcmFloat(v[i]);
  return out;
}

// For command values: never rounds up, so a value at the hard max stays at or below it.
float ToFloatNotAbove(double x) {
  float f = ToLcmFloat(x);
  if (std::isfinite(f) && static_cast<double>(f) > x)
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

}  // namespace

lcmt_display_command ToLcm(const DisplayCommand& c) {
  lcmt_display_command m;
  m.utime = c.utime;
  m.sequence = c.sequence;
  m.source_scan_utime = c.source_scan_utime;
  m.source_sed_utime = c.source_sed_utime;
  m.display_id = c.display_id;
  m.unit = c.unit;
  m.num_actuators = static_cast<int32_t>(c.value.size());
  m.value.resize(c.value.size());
  for (std::size_t i = 0; i < c.value.size(); ++i) m.value[i] = ToFloatNotAbove(c.value[i]);
  m.clamped = c.clamped;
  m.stale = c.stale;
  m.fault = c.fault;
  m.shutdown = c.shutdown;
  return m;
}

DisplayCommand FromLcm(const lcmt_display_command& m) {
  DisplayCommand c;
  c.utime = m.utime;
  c.sequence = m.sequence;
  c.source_scan_utime = m.source_scan_utime;
  c.source_sed_utime = m.source_sed_utime;
  c.display_id = m.display_id;
  c.unit = m.unit;
  c.value.assign(m.value.begin(), m.value.end());
  c.clamped = m.clamped;
  c.stale = m.stale;
  c.fault = m.fault;
  c.shutdown = m.shutdown;
  return c;
}

lcmt_merkel_sed ToLcm(const SedField& f) {
  lcmt_merkel_sed m;
  m.utime = f.utime;
  m.source_scan_utime = f.source_scan_utime;
  m.model_id = f.model_id;
  m.num_vertices = static_cast<int32_t>(f.sed_Pa.size());
  m.sed_Pa = ToFloats(f.sed_Pa);
  const bool has_positions = f.x_mm.size() == f.sed_Pa.size() && f.y_mm.size() == f.sed_Pa.size();
  m.num_positions = has_positions ? m.num_vertices : 0;
  if (has_positions) {
    m.x_mm = ToFloats(f.x_mm);
    m.y_mm = ToFloats(f.y_mm);
    // z is optional in SedField but always sent; unknown depth is sent as 0 (the pad surface).
    if (f.z_mm.size() == f.sed_Pa.size()) m.z_mm = ToFloats(f.z_mm);
    else m.z_mm.assign(f.sed_Pa.size(), 0.0f);
  }
  m.num_ids = 0;
  m.max_sed_Pa = ToLcmFloat(MaxFiniteSed(f));
  return m;
}

SedField FromLcm(const lcmt_merkel_sed& m) {
  SedField f;
  f.utime = m.utime;
  f.source_scan_utime = m.source_scan_utime;
  f.model_id = m.model_id;
  f.sed_Pa.assign(m.sed_Pa.begin(), m.sed_Pa.end());
  f.x_mm.assign(m.x_mm.begin(), m.x_mm.end());
  f.y_mm.assign(m.y_mm.begin(), m.y_mm.end());
  f.z_mm.assign(m.z_mm.begin(), m.z_mm.end());
  return f;
}

}  // namespace sedbridge::display
