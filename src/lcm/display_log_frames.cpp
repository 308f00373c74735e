#include "lcm/display_log_frames.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "lcm/display_command_message.h"
#include "lcm/lcm_log_reader.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_bridge_status.hpp"

namespace sedbridge::lcm_io {

std::vector<DisplayFrame> ReadDisplayFrames(const std::string& log_path,
                                            const LcmChannels& channels, double fps,
                                            std::size_t max_frames, std::size_t* bad_events) {
  LcmLogReader reader(log_path);
  std::vector<DisplayFrame> frames;
  display::SedField sed;
  bool has_sed = false;
  std::vector<int8_t> taxel_health;
  bool have_next = false;
  int64_t next_frame_utime = 0;
  const int64_t period_us = fps > 0 ? static_cast<int64_t>(1e6 / fps) : 0;
  DisplayFrame last;
  bool last_kept = true;
  std::size_t bad = 0;
  while (const lcm::LogEvent* e = reader.Next()) {
    if (e->channel == channels.sed) {
      lcmt_merkel_sed m;
      if (!LcmLogReader::Decode(*e, &m)) {
        ++bad;
        continue;
      }
      sed = FromLcm(m);
      has_sed = true;
    } else if (e->channel == channels.status) {
      lcmt_bridge_status m;
      if (!LcmLogReader::Decode(*e, &m)) {
        ++bad;
        continue;
      }
      taxel_health = m.taxel_health;
    } else if (e->channel == channels.command) {
      lcmt_display_command m;
      if (!LcmLogReader::Decode(*e, &m)) {
        ++bad;
        continue;
      }
      DisplayFrame f;
      f.log_utime = e->timestamp;
      f.command = FromLcm(m);
      f.has_sed = has_sed;
      if (has_sed) f.sed = sed;
      f.taxel_health = taxel_health;
      if (frames.size() < max_frames && (!have_next || e->timestamp >= next_frame_utime)) {
        frames.push_back(f);
        have_next = true;
        next_frame_utime = e->timestamp + period_us;
        last_kept = true;
      } else {
        last = std::move(f);
        last_kept = false;
      }
    }
  }
  if (!last_kept) {
    if (frames.size() >= max_frames && !frames.empty()) frames.back() = std::move(last);
    else frames.push_back(std::move(last));
  }
  if (bad_events) *bad_events = bad;
  return frames;
}

namespace {

void Number(std::ostream& os, double x) {
  if (!std::isfinite(x)) {
    os << "null";
    return;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  os << buf;
}

void Array(std::ostream& os, const std::vector<double>& v) {
  os << '[';
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) os << ',';
    Number(os, v[i]);
  }
  os << ']';
}

std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out + '"';
}

}  // namespace

void WriteFramesJsonl(const std::string& path, const display::ActuatorLayout& layout,
                      const std::string& display_id, const std::vector<DisplayFrame>& frames) {
  std::ofstream os(path);
  if (!os) throw std::runtime_error("cannot write '" + path + "'");
  os << "{\"display_id\":" << Quoted(display_id) << ",\"unit\":" << Quoted(layout.unit)
     << ",\"max\":";
  Number(os, layout.max);
  os << ",\"x_mm\":";
  Array(os, layout.x_mm);
  os << ",\"y_mm\":";
  Array(os, layout.y_mm);
  os << "}\n";
  for (const DisplayFrame& f : frames) {
    const display::DisplayCommand& c = f.command;
    os << "{\"utime\":" << f.log_utime << ",\"sequence\":" << c.sequence << ",\"value\":";
    Array(os, c.value);
    os << ",\"clamped\":" << (c.clamped ? "true" : "false")
       << ",\"stale\":" << (c.stale ? "true" : "false")
       << ",\"fault\":" << (c.fault ? "true" : "false")
       << ",\"shutdown\":" << (c.shutdown ? "true" : "false") << ",\"sed\":";
    const bool usable = f.has_sed && f.sed.x_mm.size() == f.sed.size() && f.sed.y_mm.size() == f.sed.size();
    if (!usable) {
      os << "null";
    } else {
      os << "{\"x_mm\":";
      Array(os, f.sed.x_mm);
      os << ",\"y_mm\":";
      Array(os, f.sed.y_mm);
      os << ",\"z_mm\":";
      Array(os, f.sed.z_mm);
      os << ",\"sed_Pa\":";
      Array(os, f.sed.sed_Pa);
      os << '}';
    }
    os << "}\n";
  }
  if (!os) throw std::runtime_error("write error on '" + path + "'");
}

}  // namespace sedbridge::lcm_io
