#include "sensors/scan_assembler.h"

#include <linux/can/error.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sedbridge::sensors {
namespace {

// Default tare "quiet" band as a fraction of the raw range [-]: wide enough for a resting
// sensor's noise and drift, narrow enough that a touch during the tare is not averaged in.
constexpr double kDefaultQuietFractionOfRange = 0.02;

}  // namespace

ScanAssembler::ScanAssembler(const SensorProfile& profile, AssemblerOptions options)
    : profile_(profile),
      codec_(profile),
      options_(options),
      half_period_us_(static_cast<int64_t>(0.5e6 / profile.scan_rate_Hz)) {
  const int slots = profile_.layout.frame_count;
  const int channels = profile_.channel_count();
  slot_received_.assign(slots, 0);
  slot_frame_.assign(slots, Frame{});
  slot_seen_.assign(slots, 0);
  slot_counter_.assign(slots, -1);
  raw_.assign(channels, 0);
  raw_known_.assign(channels, 0);
  previous_raw_.assign(channels, 0);
  same_count_.assign(channels, 0);
  baseline_.resize(channels);
  for (int ch = 0; ch < channels; ++ch)
    baseline_[ch] = profile_.calibration.offset_counts[ch % profile_.axes];
  quiet_tolerance_ = options_.quiet_tolerance_counts > 0
                         ? options_.quiet_tolerance_counts
                         : kDefaultQuietFractionOfRange * static_cast<double>(profile_.RawMax() - profile_.RawMin());
  if (options_.tare_scans > 0) RequestTare(options_.tare_scans);
}

void ScanAssembler::RequestTare(int scans) {
  tare_wanted_ = scans;
  tare_collected_ = 0;
  tare_sum_.assign(raw_.size(), 0.0);
}

void ScanAssembler::StartScan(const DecodedFrame& d, int64_t utime) {
  active_ = true;
  first_utime_ = utime;
  counter_ = d.scan_counter;
  received_ = 0;
  max_slot_ = -1;
  std::fill(slot_received_.begin(), slot_received_.end(), 0);
  if (d.scan_counter >= 0 && have_last_counter_) {
    const int64_t modulus = int64_t{1} << profile_.layout.scan_counter.bits;
    const int64_t gap = ((d.scan_counter - last_counter_ - 1) % modulus + modulus) % modulus;
    counters_.scans_dropped += gap;
  }
}

void ScanAssembler::Push(const Frame& f, std::vector<Scan>* out) {
  ++counters_.frames;
  // One sensor, one bus: frames from another interface (a candump of can0 and can1) are
  // never merged into this sensor's scans.
  if (!options_.interface.empty() && f.Interface() != options_.interface) {
    ++counters_.other_interface;
    return;
  }
  if (f.error) TrackBusState(f);
  DecodedFrame d;
  switch (codec_.Decode(f, &d)) {
    case DecodeStatus::kOk: break;
    case DecodeStatus::kUnknownId: ++counters_.unknown_id; return;
    case DecodeStatus::kWrongLength: ++counters_.wrong_length; return;
    case DecodeStatus::kWrongFrameType: ++counters_.wrong_frame_type; return;
    case DecodeStatus::kRemoteFrame: ++counters_.remote_frames; return;
    case DecodeStatus::kErrorFrame: ++counters_.error_frames; return;
    case DecodeStatus::kBadFrameIndex: ++counters_.bad_frame_index; return;
  }
  const int slot = d.slot;
  const bool has_counter = d.scan_counter >= 0;

  // Duplicate: the slot's last frame again, same payload, same scan.
  if (slot_seen_[slot] && f.SamePayload(slot_frame_[slot])) {
    const bool same_scan = has_counter ? slot_counter_[slot] == d.scan_counter
                                       : std::llabs(f.utime - slot_frame_[slot].utime) < half_period_us_;
    if (same_scan) {
      ++counters_.duplicates;
      return;
    }
  }

  if (active_ && f.utime - first_utime_ > profile_.partial_timeout_us) Emit(false, out);

  // Stale: from a scan older than the current / last emitted one.
  if (has_counter) {
    const int64_t ref = active_ ? counter_ : (have_last_counter_ ? last_counter_ : -1);
    if (ref >= 0) {
      const int64_t modulus = int64_t{1} << profile_.layout.scan_counter.bits;
      const int64_t behind = ((ref - d.scan_counter) % modulus + modulus) % modulus;
      const bool is_behind = (!active_ && behind == 0) || (behind > 0 && behind < modulus / 2);
      if (is_behind) {
        ++counters_.stale_frames;
        return;
      }
    }
    if (active_ && d.scan_counter != counter_) Emit(false, out);
  } else {
    if (emitted_any_ && f.utime < last_emitted_utime_) {
      ++counters_.stale_frames;
      return;
    }
    // Frames of one scan come as a burst: a repeated slot, or an idle gap longer than half
    // a scan period, means the scan in progress is over (without this, one lost or
    // corrupted frame would misalign every later scan).
    if (active_ && (slot_received_[slot] || f.utime - last_utime_ > half_period_us_)) Emit(false, out);
  }

  if (!active_) StartScan(d, f.utime);
  if (slot < max_slot_) ++counters_.reordered;
  max_slot_ = std::max(max_slot_, slot);
  for (int j = 0; j < d.channel_count; ++j) {
    raw_[d.first_channel + j] = d.samples[j];
    raw_known_[d.first_channel + j] = 1;
  }
  slot_received_[slot] = 1;
  slot_frame_[slot] = f;
  slot_seen_[slot] = 1;
  slot_counter_[slot] = d.scan_counter;
  ++received_;
  ++counters_.frames_used;
  last_utime_ = f.utime;
  if (received_ == profile_.layout.frame_count) Emit(true, out);
}

void ScanAssembler::Poll(int64_t now_utime, std::vector<Scan>* out) {
  if (active_ && now_utime - first_utime_ > profile_.partial_timeout_us) Emit(false, out);
}

void ScanAssembler::Flush(std::vector<Scan>* out) {
  if (active_) Emit(received_ == profile_.layout.frame_count, out);
}

void ScanAssembler::Emit(bool complete, std::vector<Scan>* out) {
  const int taxels = profile_.taxel_count, axes = profile_.axes;
  const int spf = profile_.layout.samples_per_frame;
  Scan s;
  s.utime = last_utime_;
  s.sequence = sequence_++;
  s.sensor_counter = counter_;
  s.complete = complete;
  s.num_taxels = taxels;
  s.num_axes = axes;
  s.raw_counts = raw_;
  s.flags.assign(taxels, 0);
  const Calibration& cal = profile_.calibration;
  for (int ch = 0; ch < taxels * axes; ++ch) {
    const int taxel = ch / axes;
    const bool fresh = slot_received_[ch / spf] != 0;
    if (!fresh) s.flags[taxel] |= kTaxelMissing;
    if (!raw_known_[ch]) s.raw_counts[ch] = 0;
    if (fresh && raw_[ch] == previous_raw_[ch]) {
      ++same_count_[ch];
    } else if (fresh) {
      same_count_[ch] = 0;
    }
    if (fresh) previous_raw_[ch] = raw_[ch];
    if (profile_.stale_after_scans > 0 && same_count_[ch] >= profile_.stale_after_scans) {
      if (!(s.flags[taxel] & kTaxelStale)) ++counters_.stale_taxels;
      s.flags[taxel] |= kTaxelStale;
    }
    if (fresh && (raw_[ch] <= cal.saturation_low_counts || raw_[ch] >= cal.saturation_high_counts)) {
      s.flags[taxel] |= kTaxelSaturated;
      ++counters_.saturated_values;
    }
  }
  Calibrate(&s);
  s.valid.resize(taxels);
  // Saturated stays valid at full scale (flag kept): treating it as missing made the
  // hardest contact give zero feedback.
  for (int i = 0; i < taxels; ++i) s.valid[i] = (s.flags[i] & ~kTaxelSaturated) == 0;
  s.tared = tared_;

  if (complete) {
    ++counters_.scans_complete;
  } else {
    ++counters_.scans_partial;
    counters_.missing_frames += profile_.layout.frame_count - received_;
  }
  if (counter_ >= 0) {
    have_last_counter_ = true;
    last_counter_ = counter_;
  }
  emitted_any_ = true;
  last_emitted_utime_ = last_utime_;
  active_ = false;
  UpdateTare(s);
  out->push_back(std::move(s));
}

void ScanAssembler::TrackBusState(const Frame& f) {
  // Error class in the id, controller detail in data[1] (linux/can/error.h).
  const uint8_t controller = f.len > 1 ? f.data[1] : 0;
  if (f.id & CAN_ERR_BUSOFF) {
    ++counters_.bus_off_events;
    counters_.bus_state = kBusOff;
  } else if ((f.id & CAN_ERR_CRTL) && (controller & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE))) {
    ++counters_.error_passive_events;
    if (counters_.bus_state < kBusErrorPassive) counters_.bus_state = kBusErrorPassive;
  }
  // Back to normal only when the controller says so.
  if ((f.id & CAN_ERR_RESTARTED) || ((f.id & CAN_ERR_CRTL) && (controller & CAN_ERR_CRTL_ACTIVE)))
    counters_.bus_state = kBusErrorActive;
}

void ScanAssembler::Calibrate(Scan* s) {
  const int taxels = profile_.taxel_count, axes = profile_.axes;
  const Calibration& cal = profile_.calibration;
  const double area_m2 = profile_.taxel_area_mm2() * 1e-6;
  double to_Pa = 1.0;
  if (cal.unit == CalibrationUnit::kKiloPascal) to_Pa = 1e3;
  if (cal.unit == CalibrationUnit::kNewton) to_Pa = 1.0 / area_m2;
  s->pressure_Pa.assign(taxels, 0.0);
  s->force_N.assign(taxels, 0.0);
  if (axes == 3) {
    s->shear_x_Pa.assign(taxels, 0.0);
    s->shear_y_Pa.assign(taxels, 0.0);
  }
  const int normal = profile_.NormalAxis();
  double v[3] = {0, 0, 0};
  for (int i = 0; i < taxels; ++i) {
    bool finite = true;
    for (int a = 0; a < axes; ++a) {
      const int ch = i * axes + a;
      v[a] = (s->raw_counts[ch] - baseline_[ch]) * cal.scale_per_count[a] * cal.taxel_gain[i] * to_Pa;
      finite = finite && std::isfinite(v[a]);
    }
    if (!finite) {
      s->flags[i] |= kTaxelNonFinite;
      ++counters_.nonfinite_values;
      continue;  // values stay 0
    }
    s->pressure_Pa[i] = v[normal];
    s->force_N[i] = v[normal] * area_m2;
    if (axes == 3) {
      s->shear_x_Pa[i] = v[0];
      s->shear_y_Pa[i] = v[1];
    }
  }
}

void ScanAssembler::UpdateTare(const Scan& s) {
  if (tare_wanted_ <= 0) return;
  bool quiet = s.complete;
  for (uint8_t f : s.flags) quiet = quiet && (f & (kTaxelMissing | kTaxelSaturated)) == 0;
  if (quiet && tare_collected_ > 0) {
    for (size_t ch = 0; ch < raw_.size(); ++ch)
      if (std::abs(static_cast<double>(s.raw_counts[ch]) - tare_reference_[ch]) > quiet_tolerance_) {
        quiet = false;
        break;
      }
  }
  if (!quiet) {
    // Something touched the sensor (or a frame was lost): start collecting again.
    tare_collected_ = 0;
    std::fill(tare_sum_.begin(), tare_sum_.end(), 0.0);
    return;
  }
  if (tare_collected_ == 0) tare_reference_ = s.raw_counts;
  for (size_t ch = 0; ch < raw_.size(); ++ch) tare_sum_[ch] += s.raw_counts[ch];
  if (++tare_collected_ >= tare_wanted_) {
    for (size_t ch = 0; ch < raw_.size(); ++ch) baseline_[ch] = tare_sum_[ch] / tare_collected_;
    tared_ = true;
    tare_wanted_ = 0;
  }
}

std::string FormatCounters(const BadFrameCounters& c) {
  std::string s;
  auto line = [&](const char* name, int64_t v) {
    char buf[80];
    std::snprintf(buf, sizeof buf, "  %-18s %lld\n", name, static_cast<long long>(v));
    s += buf;
  };
  line("frames", c.frames);
  line("frames_used", c.frames_used);
  line("unknown_id", c.unknown_id);
  line("wrong_length", c.wrong_length);
  line("wrong_frame_type", c.wrong_frame_type);
  line("bad_frame_index", c.bad_frame_index);
  line("remote_frames", c.remote_frames);
  line("error_frames", c.error_frames);
  line("bus_off_events", c.bus_off_events);
  line("error_passive_events", c.error_passive_events);
  line("bus_state", c.bus_state);
  line("other_interface", c.other_interface);
  line("duplicates", c.duplicates);
  line("stale_frames", c.stale_frames);
  line("reordered", c.reordered);
  line("scans_complete", c.scans_complete);
  line("scans_partial", c.scans_partial);
  line("missing_frames", c.missing_frames);
  line("scans_dropped", c.scans_dropped);
  line("saturated_values", c.saturated_values);
  line("nonfinite_values", c.nonfinite_values);
  line("stale_taxels", c.stale_taxels);
  return s;
}

}  // namespace sedbridge::sensors
