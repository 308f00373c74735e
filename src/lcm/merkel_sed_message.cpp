#include "lcm/merkel_sed_message.h"

#include <vector>

#include "lcm/lcm_float.h"

namespace sedbridge::lcm_io {
namespace {

std::vector<float> ToFloats(const std::vector<double>& v) {
  std::vector<float> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = ToLcmFloat(v[i]);
  return out;
}

}  // namespace

lcmt_merkel_sed ToLcm(const display::SedField& f) {
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
  m.max_sed_Pa = ToLcmFloat(display::MaxFiniteSed(f));
  return m;
}

display::SedField FromLcm(const lcmt_merkel_sed& m) {
  display::SedField f;
  f.utime = m.utime;
  f.source_scan_utime = m.source_scan_utime;
  f.model_id = m.model_id;
  f.sed_Pa.assign(m.sed_Pa.begin(), m.sed_Pa.end());
  f.x_mm.assign(m.x_mm.begin(), m.x_mm.end());
  f.y_mm.assign(m.y_mm.begin(), m.y_mm.end());
  f.z_mm.assign(m.z_mm.begin(), m.z_mm.end());
  return f;
}

}  // namespace sedbridge::lcm_io
