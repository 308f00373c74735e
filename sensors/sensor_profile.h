#pragma once
// A tactile sensor profile (config/sensors/*.yaml): which CAN frames carry which taxel
// readings, where the taxels sit on the sensor pad, and how raw counts become pressure.
// The decoder and the encoder (taxel_codec.h) are both built from this one description.
//
// Conventions
//   - A "channel" is one raw reading: channel = taxel * axes + axis. With axes == 3 the
//     axis order is x, y (shear, in the pad plane) and z (normal, pressing into the pad
//     is positive); with axes == 1 the only axis is the normal one.
//   - Pad frame: x, y in the pad surface, z along the outward pad normal; taxel positions
//     are the taxel centres in mm.
//   - One scan is `frame_count` frame slots; slot k carries channels
//     [k * samples_per_frame, (k + 1) * samples_per_frame); trailing samples past the last
//     channel are padding (encoded 0, ignored when decoding).
//   - A slot is identified by its CAN id (ids[k]) or, when `frame_index` is present, by
//     that field in the payload (all slots then share ids[0]).
//   - Bit numbering: byte_order "big" counts bit 0 as the MSB of byte 0 and packs each
//     sample MSB first (Motorola); "little" counts bit 0 as the LSB of byte 0 and packs LSB
//     first (Intel). The same numbering is used for frame_index and scan_counter.
// The YAML keys are documented in config/sensors/README.md.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/name_value.h"
#include "sensors/can_frame.h"
#include "sensors/tactile_model_params.h"
#include "sensors/taxel_health_thresholds.h"

namespace sedbridge::sensors {

/// Most taxels a profile may have (taxels.count) and most frame slots an `id_base` profile
/// may expand to (frames.count): larger values are typos, and would allocate per slot.
inline constexpr int kMaxTaxelCount = 4096;
inline constexpr int kMaxFrameSlots = 4096;

enum class ByteOrder { kBig, kLittle };
/// "big", "little" (key frames.byte_order).
const config::EnumNames<ByteOrder>& NamesOf(ByteOrder);

/// A bit field inside a frame payload; bits == 0 means "absent".
struct BitField {
  int first_bit = 0;
  int bits = 0;
  bool present() const { return bits > 0; }

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(config::Field("first_bit", &first_bit).Required().NonNegative());
    a->Visit(config::Field("bits", &bits).Required().InRange(1, 24));
  }
};

struct FrameLayout {
  std::vector<uint32_t> ids;  ///< one per slot, or a single shared id with frame_index
  bool extended_ids = false;  ///< 29-bit identifiers
  bool fd = false;            ///< CAN FD frames
  uint8_t fd_flags = 0;       ///< CanFdFlags the encoder sets (BRS usually)
  int frame_count = 0;        ///< slots per scan
  int length = 8;             ///< payload bytes every frame must have
  int samples_per_frame = 0;
  int sample_bits = 16;       ///< 1..24
  bool sample_signed = false;
  ByteOrder byte_order = ByteOrder::kBig;
  int first_sample_bit = 0;   ///< samples are contiguous from here
  BitField frame_index;       ///< slot number in the payload (libbarrett's group nibble)
  BitField scan_counter;      ///< rolling scan counter, wraps at 2^bits

  /// Keys of `frames`. `ids` xor `id_base`/`id_step` (then `count` is required and ids are
  /// expanded), and the layout as a whole, are checked by sensor_profile.cpp.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("ids", &ids));
    a->HandRead("id_base");
    a->HandRead("id_step");
    a->Visit(Field("count", &frame_count).AtLeast(1));  // default: one slot per id
    a->Visit(Field("extended_ids", &extended_ids));
    a->Visit(Field("fd", &fd));
    int fd_flags_given = fd ? kCanFdBrs : 0;
    a->Visit(Field("fd_flags", &fd_flags_given).InRange(0, 255));
    fd_flags = static_cast<uint8_t>(fd_flags_given);
    a->Visit(Field("length", &length).Required());  // 1..8, or a CAN FD length: ValidateProfile
    a->Visit(Field("samples_per_frame", &samples_per_frame).Required().AtLeast(1));
    // Range checked here: the calibration defaults shift by it (sample_bits 73 was a UB shift).
    a->Visit(Field("sample_bits", &sample_bits).Required().InRange(1, 24));
    a->Visit(Field("signed", &sample_signed));
    a->Visit(Field("byte_order", &byte_order).Required());
    a->Visit(Field("first_sample_bit", &first_sample_bit).NonNegative());
    a->Visit(Field("frame_index", &frame_index));
    a->Visit(Field("scan_counter", &scan_counter));
  }
};

/// Calibrated unit of (raw - offset) * scale.
enum class CalibrationUnit { kPascal, kKiloPascal, kNewton };
/// "Pa", "kPa", "N" (key calibration.unit).
const config::EnumNames<CalibrationUnit>& NamesOf(CalibrationUnit);

struct Calibration {
  CalibrationUnit unit = CalibrationUnit::kKiloPascal;
  std::vector<double> scale_per_count;   ///< per axis [unit/count]
  std::vector<double> offset_counts;     ///< per axis [count], zero-load reading before tare
  std::vector<double> taxel_gain;        ///< per taxel [-], all 1 by default
  /// Readings <= saturation_low or >= saturation_high are saturated (invalid).
  int64_t saturation_low_counts = 0;
  int64_t saturation_high_counts = 0;
};

struct TaxelPosition {
  double x_mm = 0;
  double y_mm = 0;
};

struct SensorProfile {
  std::string name;         ///< e.g. "uskin_4x4"
  std::string description;  ///< free text (model, which public driver it follows)
  std::string file;         ///< where it was loaded from ("" if built in code)

  int taxel_count = 0;
  int axes = 1;  ///< 1 (normal only) or 3 (x, y shear + z normal)
  std::vector<TaxelPosition> taxels;  ///< taxel centres on the pad [mm]
  double taxel_width_mm = 0;   ///< sensing element size along x
  double taxel_height_mm = 0;  ///< sensing element size along y
  double taxel_area_mm2() const { return taxel_width_mm * taxel_height_mm; }

  FrameLayout layout;
  Calibration calibration;

  double scan_rate_Hz = 100;   ///< expected scans per second
  /// A scan still incomplete this long after its first frame is emitted as partial [us].
  int64_t partial_timeout_us = 0;
  /// A taxel whose raw reading is bit-identical for this many scans is stale (0 = off).
  int stale_after_scans = 0;

  std::vector<Frame> start_frames;  ///< sent to start streaming (may be empty)
  std::vector<Frame> stop_frames;   ///< sent to stop streaming
  /// Calibrated forward model of the sensor's elastomer (key `forward_model`), used by the
  /// contact reconstruction and the simulated sensor's `pad: {model: kernel}`.
  bool has_forward_model = false;
  TactileModelParams forward_model;
  /// When a taxel is judged frozen, stuck high, dead or drifting (key `taxel_health`,
  /// sensors/taxel_health.h).
  TaxelHealthThresholds taxel_health;

  int channel_count() const { return taxel_count * axes; }
  /// Range a sample can hold.
  int64_t RawMin() const;
  int64_t RawMax() const;
  /// calibration.saturation_counts when the file gives none: the top of the sample range,
  /// and the bottom too for signed samples.
  std::array<int64_t, 2> DefaultSaturationCounts() const;
  /// Normal-axis index inside a taxel's channels (2 for 3-axis, 0 otherwise).
  int NormalAxis() const { return axes == 3 ? 2 : 0; }

  /// Every key of a profile (config/sensors/README.md). Keys whose file form is not the
  /// member's (a grid of taxels, one number for every axis, candump frames) are hand-read by
  /// sensor_profile.cpp, which also checks what spans keys (axes, grid size, the layout).
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("name", &name).Required());
    a->Visit(Field("description", &description));
    a->Section("taxels", [&](auto* t) {
      t->Visit(Field("count", &taxel_count).Required().InRange(1, kMaxTaxelCount));
      t->Visit(Field("axes", &axes).Required());  // 1 or 3
      t->HandRead("grid");
      t->HandRead("positions_mm");
      std::array<double, 2> size_mm{taxel_width_mm, taxel_height_mm};
      t->Visit(Field("size_mm", &size_mm).Required().Positive());
      taxel_width_mm = size_mm[0];
      taxel_height_mm = size_mm[1];
    });
    a->Visit(Field("frames", &layout).Required());
    a->Section("calibration", [&](auto* c) {
      c->Visit(Field("unit", &calibration.unit).Required());
      c->HandRead("scale_per_count");
      c->HandRead("offset_counts");
      c->Visit(Field("taxel_gain", &calibration.taxel_gain));  // default: all 1
      std::array<int64_t, 2> saturation = DefaultSaturationCounts();
      c->Visit(Field("saturation_counts", &saturation));  // low < high
      calibration.saturation_low_counts = saturation[0];
      calibration.saturation_high_counts = saturation[1];
    });
    a->Visit(Field("scan_rate_Hz", &scan_rate_Hz).Required().Unit("Hz").Within({0, 1e6, true, true}));
    double partial_timeout_ms = 1500.0 / scan_rate_Hz;  // default: 1.5 scan periods
    a->Visit(Field("partial_timeout_ms", &partial_timeout_ms).Positive());
    partial_timeout_us = static_cast<int64_t>(partial_timeout_ms * 1000.0);
    a->HandRead("forward_model");  // ParseTactileModelParams
    a->Visit(Field("stale_after_scans", &stale_after_scans).NonNegative());
    a->Visit(Field("taxel_health", &taxel_health));
    a->HandRead("start_frames");
    a->HandRead("stop_frames");
  }
};

/// Loads and checks a profile; errors are config::ConfigError naming file:line:column.
SensorProfile LoadSensorProfile(const std::string& path);
/// Same, from YAML text (`file` used in messages).
SensorProfile ParseSensorProfileString(const std::string& yaml, const std::string& file);

/// Resolves a profile argument: a path to a YAML file, or a shipped profile name
/// ("uskin_4x4" -> config/sensors/uskin_4x4.yaml); the rule is config::ResolveNameOrPath's.
std::string ResolveProfilePath(const std::string& name_or_path);

/// ResolveProfilePath + LoadSensorProfile; when nothing matches, the error lists the shipped
/// profiles.
SensorProfile LoadNamedSensorProfile(const std::string& name_or_path);

/// Checks internal consistency (bit fields inside the payload and not overlapping, enough
/// slots for every channel, ...). Throws std::invalid_argument. Called by the loaders;
/// call it yourself for profiles built in code.
void ValidateProfile(const SensorProfile& profile);

}  // namespace sedbridge::sensors
