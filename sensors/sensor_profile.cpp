#include "sensors/sensor_profile.h"

#include <bitset>
#include <filesystem>
#include <optional>
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

std::array<int64_t, 2> SensorProfile::DefaultSaturationCounts() const {
  // Unsigned: 0 is a reading like any other, so only the top end saturates.
  return {layout.sample_signed ? RawMin() : RawMin() - 1, RawMax()};
}

namespace {

using config::Field;
using config::MapReader;

/// The keys of `taxels.grid`.
struct TaxelGrid {
  int rows = 0;
  int cols = 0;
  std::array<double, 2> pitch_mm{};
  std::optional<std::array<double, 2>> first_mm;  ///< default: the grid centred on the pad origin

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("rows", &rows).Required().AtLeast(1));
    a->Visit(Field("cols", &cols).Required().AtLeast(1));
    a->Visit(Field("pitch_mm", &pitch_mm).Required());
    a->Visit(Field("first_mm", &first_mm));
  }
};

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

// Row-major, taxel = row * cols + col.
void ReadTaxelGrid(MapReader& taxels, SensorProfile* p) {
  MapReader g = taxels.Child("grid");
  TaxelGrid grid;
  config::ReadYaml(g, &grid);
  if (int64_t{grid.rows} * grid.cols != p->taxel_count) g.Fail("rows * cols must equal taxels.count");
  const auto& pitch = grid.pitch_mm;
  const std::array<double, 2> origin =
      grid.first_mm.value_or(std::array<double, 2>{-0.5 * (grid.cols - 1) * pitch[0], -0.5 * (grid.rows - 1) * pitch[1]});
  for (int row = 0; row < grid.rows; ++row)
    for (int col = 0; col < grid.cols; ++col)
      p->taxels.push_back({origin[0] + col * pitch[0], origin[1] + row * pitch[1]});
}

void ReadTaxelList(MapReader& taxels, SensorProfile* p) {
  std::vector<std::array<double, 2>> xy;
  config::YamlReadArchive archive(&taxels);
  archive.Visit(Field("positions_mm", &xy));
  if (static_cast<int>(xy.size()) != p->taxel_count)
    taxels.Fail(taxels.Node("positions_mm"), "'positions_mm' must list taxels.count [x, y] pairs");
  for (const auto& [x, y] : xy) p->taxels.push_back({x, y});
}

void ReadTaxels(MapReader& taxels, SensorProfile* p) {
  if (p->axes != 1 && p->axes != 3) taxels.Fail(taxels.Node("axes"), "'axes' must be 1 (normal) or 3 (x, y, z)");
  if (taxels.Has("grid") == taxels.Has("positions_mm")) taxels.Fail("give exactly one of 'grid' and 'positions_mm'");
  if (taxels.Has("grid")) {
    ReadTaxelGrid(taxels, p);
  } else {
    ReadTaxelList(taxels, p);
  }
}

// One id per slot from `ids` as given, or id_base + k * id_step; with frame_index every slot
// shares the first id.
void ReadSlotIds(MapReader& frames, FrameLayout* l) {
  if (frames.Has("ids") == frames.Has("id_base")) frames.Fail("give exactly one of 'ids' and 'id_base'");
  if (frames.Has("ids")) {
    if (l->ids.empty()) frames.Fail(frames.Node("ids"), "'ids' must not be empty");
    if (frames.Has("id_step")) frames.Fail(frames.Node("id_step"), "'id_step' goes with 'id_base', not 'ids'");
    if (frames.Has("count")) return;
    if (l->frame_index.present()) frames.Fail("missing required key 'count'");
    l->frame_count = static_cast<int>(l->ids.size());
    return;
  }
  const uint32_t base = frames.Required<uint32_t>("id_base");
  const uint32_t step = frames.Optional<uint32_t>("id_step", 1);
  if (!frames.Has("count")) frames.Fail("missing required key 'count'");
  if (l->frame_count > kMaxFrameSlots) frames.Fail(frames.Node("count"), "'count' must be 1..4096");
  if (l->frame_index.present()) {
    l->ids = {base};
    return;
  }
  for (int k = 0; k < l->frame_count; ++k) l->ids.push_back(base + step * static_cast<uint32_t>(k));
}

void ReadCalibration(MapReader& r, SensorProfile* p) {
  Calibration& c = p->calibration;
  r.Node("scale_per_count");  // presence check with the "missing key" message
  c.scale_per_count = PerAxis(r, "scale_per_count", p->axes, 0);
  c.offset_counts = PerAxis(r, "offset_counts", p->axes, 0);
  for (double s : c.scale_per_count)
    if (s == 0) r.Fail(r.Node("scale_per_count"), "'scale_per_count' must be finite and non-zero");
  if (!r.Has("taxel_gain")) c.taxel_gain.assign(p->taxel_count, 1.0);
  if (static_cast<int>(c.taxel_gain.size()) != p->taxel_count)
    r.Fail(r.Node("taxel_gain"), "'taxel_gain' needs one number per taxel");
  if (c.saturation_low_counts >= c.saturation_high_counts)
    r.Fail(r.Node("saturation_counts"), "'saturation_counts' needs [low, high], low < high");
}

void ReadForwardModel(MapReader& r, SensorProfile* p) {
  if (!r.Has("forward_model")) return;
  MapReader fm = r.Child("forward_model");
  p->forward_model = ParseTactileModelParams(fm);
  fm.Finish();
  p->has_forward_model = true;
}

SensorProfile ParseSensorProfile(MapReader& r) {
  SensorProfile p;
  p.file = r.file();
  config::YamlReadArchive archive(&r);
  p.Serialize(&archive);
  MapReader taxels = r.Child("taxels");
  ReadTaxels(taxels, &p);
  MapReader frames = r.Child("frames");
  ReadSlotIds(frames, &p.layout);
  MapReader calibration = r.Child("calibration");
  ReadCalibration(calibration, &p);
  ReadForwardModel(r, &p);
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
