#pragma once
// One assembled scan of the follower finger's tactile sensor: what the bridge consumes.
//
//   const SensorProfile& profile = ...;            // taxel positions: profile.taxels[i].x_mm
//   for (const Scan& s : scans)
//     for (int i = 0; i < s.num_taxels; ++i)
//       if (s.valid[i]) ApplyPressure(profile.taxels[i], s.pressure_Pa[i], s.utime);

#include <cstdint>
#include <vector>

namespace sedbridge::sensors {

/// Why a taxel is not valid in a scan (bit mask per taxel).
enum TaxelFlags : uint8_t {
  kTaxelMissing = 0x01,    ///< its frame did not arrive (value carried from an older scan)
  /// A raw reading at or beyond the saturation limits. The taxel stays VALID with its
  /// full-scale value (a lower bound of the true load): the hardest contact must never
  /// read as no contact.
  kTaxelSaturated = 0x02,
  kTaxelNonFinite = 0x04,  ///< calibration produced NaN/inf (value set to 0)
  kTaxelStale = 0x08,      ///< raw reading bit-identical for profile.stale_after_scans scans
  /// Judged faulty by taxel health (sensors/taxel_health.h: frozen, stuck high, dead) and
  /// left out until it behaves again; set only on the scan TaxelHealth::Apply returns.
  kTaxelMasked = 0x10,
};

struct Scan {
  /// Receive time of the frame that completed the scan (of the last frame received, for a
  /// partial scan) [us since the Unix epoch].
  int64_t utime = 0;
  /// Scans emitted by this assembler so far (0, 1, 2, ...); gaps never occur here.
  int64_t sequence = 0;
  /// The sensor's own scan counter (profile scan_counter field), -1 if it has none.
  int64_t sensor_counter = -1;
  /// All frame slots arrived. A partial scan (false) was emitted on timeout or because
  /// the next scan began; its missing taxels carry kTaxelMissing.
  bool complete = false;
  /// Calibrated against a tare baseline (false: the profile's offset_counts were used).
  bool tared = false;

  int num_taxels = 0;
  int num_axes = 1;  ///< 1 = normal only, 3 = x, y shear + z normal

  /// Raw readings as decoded, channel = taxel * num_axes + axis [counts].
  std::vector<int32_t> raw_counts;
  /// Calibrated normal pressure per taxel, compression positive [Pa]. 0 where invalid
  /// because non-finite.
  std::vector<double> pressure_Pa;
  /// Shear traction per taxel along pad x and y [Pa]; empty for a normal-only sensor.
  std::vector<double> shear_x_Pa;
  std::vector<double> shear_y_Pa;
  /// Normal force per taxel = pressure_Pa * taxel area [N].
  std::vector<double> force_N;
  /// 1 if the taxel's reading is fresh and finite (saturated readings are valid, at full
  /// scale, and flagged).
  std::vector<uint8_t> valid;
  /// TaxelFlags per taxel (0 or kTaxelSaturated when valid).
  std::vector<uint8_t> flags;

  int SaturatedCount() const {
    int n = 0;
    for (uint8_t f : flags) n += (f & kTaxelSaturated) != 0;
    return n;
  }

  int ValidCount() const {
    int n = 0;
    for (uint8_t v : valid) n += v;
    return n;
  }
};

}  // namespace sedbridge::sensors
