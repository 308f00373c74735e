#include "lcm/display_command_message.h"

#include <cmath>
#include <limits>

#include "lcm/lcm_float.h"
#include "lcm/lcm_safe_decode.h"

namespace sedbridge::lcm_io {
namespace {

// For command values: never rounds up, so a value at the hard max stays at or below it.
float ToFloatNotAbove(double x) {
  float f = ToLcmFloat(x);
  if (std::isfinite(f) && static_cast<double>(f) > x)
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

}  // namespace

lcmt_display_command ToLcm(const display::DisplayCommand& c) {
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

display::DisplayCommand FromLcm(const lcmt_display_command& m) {
  display::DisplayCommand c;
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

bool DecodeDisplayCommand(const void* data, std::size_t size, display::DisplayCommand* out) {
  lcmt_display_command m;
  if (!SafeDecode(data, size, &m)) return false;
  *out = FromLcm(m);
  return true;
}

}  // namespace sedbridge::lcm_io
