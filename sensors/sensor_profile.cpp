#include "sensors/sensor_profile.h"

#include <bitset>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "common/resource_path.h"
#include "common/yaml_read_archive.h"
#include "sensors/candump_log.h"

namespace sedbridge::sensors {

const config::EnumNames<ByteOrder>& NamesOf(ByteOrder) {
  static const config::EnumNames<ByteOrder> names{{ByteOrder::kBig, "big"}, {ByteOrder::kLittle, "little"}};
  return names;
}

const config::EnumNames<CalibrationUnit>& NamesOf(CalibrationUnit) {
  static const config::EnumNames<CalibrationUnit> names{
      {CalibrationUnit::kPascal, "Pa"}, {CalibrationUnit::kKiloPascal, "kPa"}, {CalibrationUnit::kNewton, "N"}};
  return names;
}

int64_t SensorProfile::RawMin() const {
  return layout.sample_signed ? -(int64_t{1} << (layout.sample_bits - 1)) : 0;
}

int64_t SensorProfile::RawMax() const {
  return layout.sample_signed ? (int64_t{1} << (layout.sample_bits - 1)) - 1
                              : (int64_t{1} << layout.sample_bits) - 1;
}

namespace {

using config::MapReader;

/// A list of `n` doubles, or one number repeated n times.
std::vector<double> PerAxis(MapReader& r, const std::string& key, int n, double fallback) {
  if (!r.Has(key)) return std::vector<double>(n, fallback);
  const YAML::Node node = r.Node(key);
  if (node.IsScalar()) return std::vector<double>(n, config::As<double>(node, r.file(), key));
  auto v = config::As<std::vector<double>>(node, r.file(), key);
  if (static_cast<int>(v.size()) != n)
    r.Fail(node, "'" + key + "' needs one number or " + std::to_string(n) + " (one per axis)");
  return v;
}

BitField ParseBitField(MapReader& parent, const char* key) {
  BitField f;
  config::YamlReadArchive archive(&parent);
  archive.Visit(config::Field(key, &f));
  return f;
}

Frame ParseCommandFrame(const YAML::Node& node, const std::string& file) {
  const std::string text = config::As<std::string>(node, file, "command frame");
  Frame f;
  const LineResult r = ParseCandumpLine("(0.000000) can0 " + text, &f);
  if (r.kind != LineKind::kFrame)
    throw config::ConfigError(config::LocationOf(node, file),
                              "command frame '" + text + "' is not candump syntax (e.g. 201#0700): " +
                                  (r.error ? r.error : "empty"));
  f.interface.fill('\0');
  return f;
}

std::vector<Frame> ParseCommandFrames(MapReader& r, const std::string& key) {
  std::vector<Frame> out;
  if (!r.Has(key)) return out;
  const YAML::Node list = r.Node(key);
  if (!list.IsSequence()) r.Fail(list, "'" + key + "' must be a list of frames like \"201#0700\"");
  for (const auto& item : list) out.push_back(ParseCommandFrame(item, r.file()));
  return out;
}

void ParseTaxels(MapReader& r, SensorProfile* p) {
  p->taxel_count = r.Required<int>("count");
  if (p->taxel_count < 1 || p->taxel_count > 4096) r.Fail(r.Node("count"), "'count' must be 1..4096");
  p->axes = r.Required<int>("axes");
  if (p->axes != 1 && p->axes != 3) r.Fail(r.Node("axes"), "'axes' must be 1 (normal) or 3 (x, y, z)");
  const auto size = r.Required<std::vector<double>>("size_mm");
  if (size.size() != 2 || !(size[0] > 0) || !(size[1] > 0))
    r.Fail(r.Node("size_mm"), "'size_mm' needs two positive numbers [width, height]");
  p->taxel_width_mm = size[0];
  p->taxel_height_mm = size[1];
  if (r.Has("grid") == r.Has("positions_mm"))
    r.Fail("give exactly one of 'grid' and 'positions_mm'");
  if (r.Has("grid")) {
    MapReader g = r.Child("grid");
    const int rows = g.Required<int>("rows"), cols = g.Required<int>("cols");
    const auto pitch = g.Required<std::vector<double>>("pitch_mm");
    if (pitch.size() != 2) g.Fail(g.Node("pitch_mm"), "'pitch_mm' needs [x, y]");
    if (rows < 1 || cols < 1 || rows * cols != p->taxel_count)
      g.Fail("rows * cols must equal taxels.count");
    // Centred on the pad origin unless told otherwise; row-major, taxel = row * cols + col.
    std::vector<double> origin = {-0.5 * (cols - 1) * pitch[0], -0.5 * (rows - 1) * pitch[1]};
    if (g.Has("first_mm")) {
      origin = g.Required<std::vector<double>>("first_mm");
      if (origin.size() != 2) g.Fail(g.Node("first_mm"), "'first_mm' needs [x, y]");
    }
    g.Finish();
    for (int row = 0; row < rows; ++row)
      for (int col = 0; col < cols; ++col)
        p->taxels.push_back({origin[0] + col * pitch[0], origin[1] + row * pitch[1]});
  } else {
    const YAML::Node list = r.Node("positions_mm");
    if (!list.IsSequence() || static_cast<int>(list.size()) != p->taxel_count)
      r.Fail(list, "'positions_mm' must list taxels.count [x, y] pairs");
    for (const auto& item : list) {
      auto xy = config::As<std::vector<double>>(item, r.file(), "positions_mm");
      if (xy.size() != 2)
        throw config::ConfigError(config::LocationOf(item, r.file()), "a position needs [x, y]");
      p->taxels.push_back({xy[0], xy[1]});
    }
  }
}

void ParseFrames(MapReader& r, SensorProfile* p) {
  FrameLayout& l = p->layout;
  l.extended_ids = r.Optional<bool>("extended_ids", false);
  l.fd = r.Optional<bool>("fd", false);
  l.fd_flags = static_cast<uint8_t>(r.Optional<int>("fd_flags", l.fd ? kCanFdBrs : 0));
  l.length = r.Required<int>("length");
  l.samples_per_frame = r.Required<int>("samples_per_frame");
  l.sample_bits = r.Required<int>("sample_bits");
  // Checked here, not only in ValidateProfile: the calibration defaults (RawMax) shift by it
  // before validation runs (found by fuzz_yaml_configs: sample_bits 73 was a UB shift).
  if (l.sample_bits < 1 || l.sample_bits > 24) r.Fail(r.Node("sample_bits"), "'sample_bits' must be 1..24");
  l.sample_signed = r.Optional<bool>("signed", false);
  config::YamlReadArchive archive(&r);
  archive.Visit(config::Field("byte_order", &l.byte_order).Required());
  l.first_sample_bit = r.Optional<int>("first_sample_bit", 0);
  l.frame_index = ParseBitField(r, "frame_index");
  l.scan_counter = ParseBitField(r, "scan_counter");
  if (r.Has("ids") == r.Has("id_base")) r.Fail("give exactly one of 'ids' and 'id_base'");
  if (r.Has("ids")) {
    l.ids = r.Required<std::vector<uint32_t>>("ids");
    if (l.ids.empty()) r.Fail(r.Node("ids"), "'ids' must not be empty");
    l.frame_count = l.frame_index.present() ? r.Required<int>("count")
                                            : r.Optional<int>("count", static_cast<int>(l.ids.size()));
  } else {
    const uint32_t base = r.Required<uint32_t>("id_base");
    const uint32_t step = r.Optional<uint32_t>("id_step", 1);
    l.frame_count = r.Required<int>("count");
    if (l.frame_count < 1 || l.frame_count > 4096) r.Fail(r.Node("count"), "'count' must be 1..4096");
    if (l.frame_index.present()) {
      l.ids = {base};
    } else {
      for (int k = 0; k < l.frame_count; ++k) l.ids.push_back(base + step * static_cast<uint32_t>(k));
    }
  }
}

void ParseCalibration(MapReader& r, SensorProfile* p) {
  Calibration& c = p->calibration;
  config::YamlReadArchive archive(&r);
  archive.Visit(config::Field("unit", &c.unit).Required());
  r.Node("scale_per_count");  // presence check with the "missing key" message
  c.scale_per_count = PerAxis(r, "scale_per_count", p->axes, 0);
  c.offset_counts = PerAxis(r, "offset_counts", p->axes, 0);
  for (double s : c.scale_per_count)
    if (!std::isfinite(s) || s == 0) r.Fail(r.Node("scale_per_count"), "'scale_per_count' must be finite and non-zero");
  for (double o : c.offset_counts)
    if (!std::isfinite(o)) r.Fail(r.Node("offset_counts"), "'offset_counts' must be finite");
  c.taxel_gain.assign(p->taxel_count, 1.0);
  if (r.Has("taxel_gain")) {
    c.taxel_gain = r.Required<std::vector<double>>("taxel_gain");
    if (static_cast<int>(c.taxel_gain.size()) != p->taxel_count)
      r.Fail(r.Node("taxel_gain"), "'taxel_gain' needs one number per taxel");
    for (double g : c.taxel_gain)
      if (!std::isfinite(g)) r.Fail(r.Node("taxel_gain"), "'taxel_gain' entries must be finite");
  }
  c.saturation_low_counts = p->layout.sample_signed ? p->RawMin() : p->RawMin() - 1;
  c.saturation_high_counts = p->RawMax();
  if (r.Has("saturation_counts")) {
    auto s = r.Required<std::vector<int64_t>>("saturation_counts");
    if (s.size() != 2 || s[0] >= s[1]) r.Fail(r.Node("saturation_counts"), "'saturation_counts' needs [low, high], low < high");
    c.saturation_low_counts = s[0];
    c.saturation_high_counts = s[1];
  }
}

SensorProfile ParseSensorProfile(MapReader& r) {
  SensorProfile p;
  p.file = r.file();
  p.name = r.Required<std::string>("name");
  p.description = r.Optional<std::string>("description", "");
  {
    MapReader t = r.Child("taxels");
    ParseTaxels(t, &p);
    t.Finish();
  }
  MapReader frames = r.Child("frames");
  ParseFrames(frames, &p);
  frames.Finish();
  {
    MapReader c = r.Child("calibration");
    ParseCalibration(c, &p);
    c.Finish();
  }
  p.scan_rate_Hz = r.Required<double>("scan_rate_Hz");
  if (!(p.scan_rate_Hz > 0 && p.scan_rate_Hz < 1e6)) r.Fail(r.Node("scan_rate_Hz"), "'scan_rate_Hz' must be in (0, 1e6)");
  const double timeout_ms = r.Optional<double>("partial_timeout_ms", 1500.0 / p.scan_rate_Hz);
  if (!(timeout_ms > 0)) r.Fail(r.Node("partial_timeout_ms"), "'partial_timeout_ms' must be > 0");
  p.partial_timeout_us = static_cast<int64_t>(timeout_ms * 1000.0);
  if (r.Has("forward_model")) {
    config::MapReader fm = r.Child("forward_model");
    p.forward_model = ParseTactileModelParams(fm);
    fm.Finish();
    p.has_forward_model = true;
  }
  p.stale_after_scans = r.Optional<int>("stale_after_scans", 0);
  if (p.stale_after_scans < 0) r.Fail(r.Node("stale_after_scans"), "'stale_after_scans' must be >= 0");
  p.start_frames = ParseCommandFrames(r, "start_frames");
  p.stop_frames = ParseCommandFrames(r, "stop_frames");
  try {
    ValidateProfile(p);
  } catch (const std::invalid_argument& e) {
    frames.Fail(e.what());
  }
  r.Finish();
  return p;
}

}  // namespace

SensorProfile ParseSensorProfileString(const std::string& yaml, const std::string& file) {
  auto doc = config::LoadYamlString(yaml, file);
  MapReader r(doc.root, doc.file);
  return ParseSensorProfile(r);
}

SensorProfile LoadSensorProfile(const std::string& path) {
  auto doc = config::LoadYamlFile(path);
  MapReader r(doc.root, doc.file);
  return ParseSensorProfile(r);
}

std::string ResolveProfilePath(const std::string& name_or_path) {
  return config::ResolveNameOrPath(name_or_path, "config/sensors");
}

SensorProfile LoadNamedSensorProfile(const std::string& name_or_path) {
  const std::string path = ResolveProfilePath(name_or_path);
  if (!std::filesystem::exists(path)) {
    std::string shipped;
    const auto dir = std::filesystem::path(config::ResolveResource("config/sensors"));
    if (std::filesystem::is_directory(dir))
      for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".yaml") shipped += (shipped.empty() ? "" : ", ") + e.path().stem().string();
    throw config::ConfigError({name_or_path, 0, 0}, "no such sensor profile (not a file; shipped profiles: " +
                                                        (shipped.empty() ? std::string("none found") : shipped) + ")");
  }
  return LoadSensorProfile(path);
}

void ValidateProfile(const SensorProfile& p) {
  auto fail = [](const std::string& m) { throw std::invalid_argument(m); };
  const FrameLayout& l = p.layout;
  if (p.taxel_count < 1) fail("taxel count must be >= 1");
  if (p.axes != 1 && p.axes != 3) fail("axes must be 1 or 3");
  if (static_cast<int>(p.taxels.size()) != p.taxel_count) fail("one position per taxel needed");
  const int max_len = l.fd ? kCanFdMaxLen : kCanMaxLen;
  if (l.length < 1 || l.length > max_len) fail("frame length must be 1.." + std::to_string(max_len));
  if (l.fd && !IsValidFdLength(l.length)) fail("CAN FD length must be 0-8,12,16,20,24,32,48,64");
  if (l.sample_bits < 1 || l.sample_bits > 24) fail("sample_bits must be 1..24");
  if (l.samples_per_frame < 1) fail("samples_per_frame must be >= 1");
  if (l.frame_count < 1) fail("frame count must be >= 1");
  if (l.frame_count * l.samples_per_frame < p.channel_count())
    fail("frames carry " + std::to_string(l.frame_count * l.samples_per_frame) +
         " samples but the sensor has " + std::to_string(p.channel_count()) + " channels");
  if ((l.frame_count - 1) * l.samples_per_frame >= p.channel_count())
    fail("the last frame slot would carry no channel");
  const uint32_t id_max = l.extended_ids ? kCanExtIdMask : kCanStdIdMask;
  for (uint32_t id : l.ids)
    if (id > id_max) fail("CAN id above the " + std::string(l.extended_ids ? "29" : "11") + "-bit range");
  if (l.frame_index.present()) {
    if (l.ids.size() != 1) fail("with frame_index all slots share one id: give one id");
    if (l.frame_count > (1 << l.frame_index.bits)) fail("frame_index has too few bits for count");
  } else {
    if (static_cast<int>(l.ids.size()) != l.frame_count) fail("need one id per frame slot");
    for (size_t i = 0; i < l.ids.size(); ++i)
      for (size_t j = i + 1; j < l.ids.size(); ++j)
        if (l.ids[i] == l.ids[j]) fail("CAN ids of frame slots must differ");
  }
  // Every bit used at most once, inside the payload.
  std::bitset<kCanFdMaxLen * 8> used;
  auto claim = [&](int first, int bits, const char* what) {
    if (first < 0 || first + bits > l.length * 8)
      fail(std::string(what) + " lies outside the " + std::to_string(l.length) + "-byte payload");
    for (int b = first; b < first + bits; ++b) {
      if (used[b]) fail(std::string(what) + " overlaps another field at bit " + std::to_string(b));
      used[b] = true;
    }
  };
  claim(l.first_sample_bit, l.samples_per_frame * l.sample_bits, "taxel samples");
  if (l.frame_index.present()) claim(l.frame_index.first_bit, l.frame_index.bits, "frame_index");
  if (l.scan_counter.present()) claim(l.scan_counter.first_bit, l.scan_counter.bits, "scan_counter");
  const Calibration& c = p.calibration;
  if (static_cast<int>(c.scale_per_count.size()) != p.axes || static_cast<int>(c.offset_counts.size()) != p.axes)
    fail("calibration needs one scale and offset per axis");
  if (static_cast<int>(c.taxel_gain.size()) != p.taxel_count) fail("calibration needs one gain per taxel");
  if (!(p.scan_rate_Hz > 0)) fail("scan rate must be > 0");
  if (p.partial_timeout_us <= 0) fail("partial timeout must be > 0");
  if (c.unit == CalibrationUnit::kNewton && !(p.taxel_area_mm2() > 0))
    fail("a force calibration (unit N) needs the taxel size");
}

}  // namespace sedbridge::sensors
