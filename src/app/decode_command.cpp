// sedbridge decode: candump log -> scans (CSV), with counts of every bad line and frame.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/plot_runner.h"
#include "common/wall_clock.h"
#include "sensors/candump_log.h"
#include "sensors/frame_pump.h"
#include "sensors/scan_assembler.h"
#include "sensors/scan_csv.h"
#include "sensors/socketcan_source.h"
#include "sensors/taxel_health.h"
#include "sensors/taxel_health_episodes.h"
#include "sensors/taxel_heatmap.h"

namespace sedbridge::app {
namespace {

// A bad line is untrusted text: control bytes (a terminal escape sequence, say) are shown as
// \xNN instead of being sent to the terminal.
std::string Printable(const std::string& text) {
  std::string out;
  char hex[8];
  for (unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return out;
}

using namespace sedbridge::sensors;

volatile std::sig_atomic_t g_stop = 0;

// A progress line on stderr every this many log lines (a power of two: a mask test per frame).
constexpr int64_t kProgressEveryLines = int64_t{1} << 20;
// Longest wait for one live frame [us] before the assembler is polled for a timed-out scan.
constexpr int64_t kLiveFrameWaitUs = 20000;

// What the command line asks for, checked.
struct DecodeRequest {
  std::optional<std::string> log_arg;    // LOG, "-" = stdin
  std::optional<std::string> interface;  // --interface
  std::string log_path;                  // for messages: LOG or "socketcan:IFACE"
  std::optional<std::string> csv_path;
  long tare_scans = 0;
  long max_bad_lines = 0;
  std::optional<std::string> heatmap_png;
  long heatmap_scan = -1;  // -1 = the scan with the highest pressure
  double duration_s = 0;   // live only
  bool send_start_frames = false;
  std::optional<std::string> record_path;
};

void DeclareDecodeArgs(ArgParser& args) {
  args.Option("profile", "PROFILE", "sensor profile: shipped name (uskin_4x4, cyskin_16, "
              "barrett_bh8_pad) or YAML path")
      .Positional("LOG", "candump -l log (use - for stdin); omit with --interface", false)
      .Option("interface", "IFACE", "decode live frames from this SocketCAN interface (e.g. can0, vcan0)")
      .Option("duration-s", "S", "with --interface: stop after S seconds", "10")
      .Flag("start", "with --interface: send the profile's start_frames first and stop_frames at the end")
      .Option("record", "OUT", "with --interface: also write the received frames as a candump -l log")
      .Option("csv", "OUT", "write one row per scan to OUT")
      .Option("tare-scans", "N", "tare from the first N quiet scans (0 = use the profile offsets)", "0")
      .Option("heatmap-png", "OUT", "draw a taxel heatmap of one scan to OUT (also writes OUT.csv); "
              "needs /usr/bin/python3 with matplotlib")
      .Option("heatmap-scan", "N", "scan to draw (default: the one with the highest pressure)")
      .Option("show-bad-lines", "N", "list at most N bad lines", "20")
      .Epilog("examples:\n"
              "  sedbridge make-log --profile uskin_4x4 --scene config/scenes/sensor_sphere_press.yaml --out s.log\n"
              "  sedbridge decode --profile uskin_4x4 s.log --csv s.csv --heatmap-png s.png\n"
              "  sedbridge decode --profile uskin_4x4 --interface can0 --start --duration-s 5 --record live.log\n"
              "exit status: 0 when at least one scan was decoded, 1 otherwise.");
}

DecodeRequest ReadDecodeRequest(const ArgParser& args) {
  DecodeRequest r;
  r.log_arg = args.GetOptional("LOG");
  r.interface = args.GetOptional("interface");
  if (r.log_arg.has_value() == r.interface.has_value())
    throw UsageError("give either a LOG file or --interface (see sedbridge decode --help)");
  if (!r.interface && (args.Has("start") || args.Has("record")))
    throw UsageError("--start and --record need --interface");
  r.log_path = r.log_arg ? *r.log_arg : "socketcan:" + *r.interface;
  r.csv_path = args.GetOptional("csv");
  r.tare_scans = args.GetInt("tare-scans");
  r.max_bad_lines = args.GetInt("show-bad-lines");
  if (r.tare_scans < 0 || r.max_bad_lines < 0) throw UsageError("--tare-scans and --show-bad-lines must be >= 0");
  r.heatmap_png = args.GetOptional("heatmap-png");
  r.heatmap_scan = args.Has("heatmap-scan") ? args.GetInt("heatmap-scan") : -1;
  r.send_start_frames = r.interface && args.GetFlag("start");
  r.record_path = args.GetOptional("record");
  return r;
}

// Where the decoded scans go: the CSV rows, the count, and the scan kept for the heatmap.
class DecodedScans {
 public:
  DecodedScans(const SensorProfile& profile, const DecodeRequest& request) : request_(request), health_(profile) {
    if (request.csv_path) {
      csv_.open(*request.csv_path);
      if (!csv_) throw std::runtime_error("cannot write " + *request.csv_path);
      csv_ << ScanCsvHeader(profile);
    }
  }

  void Take(const Scan& s) {
    ++total_;
    if (first_utime_ < 0) first_utime_ = s.utime;
    // Taxel health as the bridge judges it (the CSV keeps the readings as decoded).
    const Scan& trusted = health_.Apply(s);
    episodes_.Observe(health_, (s.utime - first_utime_) * 1e-6);
    if (csv_.is_open()) {
      row_.clear();
      AppendScanCsvRow(s, &row_);
      csv_ << row_;
    }
    if (request_.heatmap_png) KeepForHeatmap(s, trusted);
  }

  int64_t total() const { return total_; }
  int64_t first_utime() const { return first_utime_; }  // heatmap title: time since the first scan
  bool wrote_csv() const { return csv_.is_open(); }
  const Scan* chosen() const { return have_chosen_ ? &chosen_ : nullptr; }
  /// Each taxel's health when the chosen scan was taken ("healthy", "stuck high", ...).
  const std::vector<std::string>& chosen_health() const { return chosen_health_; }
  const TaxelHealthEpisodes& taxel_health() const { return episodes_; }

 private:
  // `trusted`: the scan as taxel health passes it on (masked taxels and suspects
  // invalid); the peak is theirs, so that a stuck taxel's phantom is not drawn as the press.
  void KeepForHeatmap(const Scan& s, const Scan& trusted) {
    if (request_.heatmap_scan >= 0) {
      if (s.sequence == request_.heatmap_scan) Choose(s, trusted);
      return;
    }
    double peak = 0;
    for (int i = 0; i < trusted.num_taxels; ++i)
      if (trusted.valid[i]) peak = std::max(peak, trusted.pressure_Pa[i]);
    if (peak > chosen_peak_) Choose(s, trusted), chosen_peak_ = peak;
  }
  void Choose(const Scan& s, const Scan& trusted) {
    chosen_ = s, have_chosen_ = true;
    chosen_health_.clear();
    for (int i = 0; i < health_.taxel_count(); ++i) {
      const bool left_out = i < s.num_taxels && s.valid[i] && !(i < trusted.num_taxels && trusted.valid[i]);
      chosen_health_.push_back(health_.masked(i) || !left_out ? ToString(health_.fault(i)) : "left out");
    }
  }

  const DecodeRequest& request_;
  TaxelHealth health_;
  TaxelHealthEpisodes episodes_;
  std::ofstream csv_;
  std::string row_;
  std::vector<std::string> chosen_health_;
  int64_t total_ = 0;
  int64_t first_utime_ = -1;
  Scan chosen_;
  bool have_chosen_ = false;
  double chosen_peak_ = -1;
};

// A candump log (or stdin) through the assembler; the source keeps the line counts.
std::unique_ptr<CandumpLogSource> DecodeLog(const DecodeRequest& request, ScanAssembler& assembler,
                                            DecodedScans& scans) {
  std::unique_ptr<std::istream> in;
  if (*request.log_arg == "-") {
    in = std::make_unique<std::istream>(std::cin.rdbuf());
  } else {
    auto file = std::make_unique<std::ifstream>(*request.log_arg);
    if (!*file) throw std::runtime_error("cannot open " + *request.log_arg);
    in = std::move(file);
  }
  auto source = std::make_unique<CandumpLogSource>(std::move(in), request.log_path, PlaybackOptions{},
                                                   static_cast<size_t>(request.max_bad_lines));
  const bool tty = isatty(fileno(stderr));
  PumpOptions pump;
  pump.wall_clock_utime = WallClockUtime;
  pump.poll_on_timeout = false;  // a log at full speed never times out
  pump.on_frame = [&](const Frame&) {
    const int64_t lines = source->reader().lines_read();
    if ((lines & (kProgressEveryLines - 1)) == 0)  // progress on long logs
      std::fprintf(stderr, tty ? "\r  %lld lines, %lld scans..." : "  %lld lines, %lld scans...\n",
                   static_cast<long long>(lines), static_cast<long long>(scans.total()));
  };
  PumpFrames(*source, assembler, [&](const Scan& s, int64_t) { scans.Take(s); }, pump);
  if (tty && source->reader().lines_read() >= kProgressEveryLines) std::fprintf(stderr, "\n");
  return source;
}

// A live SocketCAN bus for --duration-s or until Ctrl-C, optionally recorded.
FrameSourceStats DecodeInterface(const ArgParser& args, const DecodeRequest& request, const SensorProfile& profile,
                                 ScanAssembler& assembler, DecodedScans& scans) {
  const double duration_s = args.GetDouble("duration-s");
  if (!(duration_s > 0)) throw UsageError("--duration-s must be > 0");
  SocketCanSource source(OptionsForProfile(profile, *request.interface));
  std::ofstream record_file;
  std::unique_ptr<CandumpLogWriter> recorder;
  if (request.record_path) {
    record_file.open(*request.record_path);
    if (!record_file) throw std::runtime_error("cannot write " + *request.record_path);
    recorder = std::make_unique<CandumpLogWriter>(record_file);
  }
  if (request.send_start_frames)
    for (const Frame& f : profile.start_frames)
      if (!source.Send(f)) std::fprintf(stderr, "warning: could not send start frame %s\n", FormatCandumpLine(f).c_str());
  g_stop = 0;
  std::signal(SIGINT, [](int) { g_stop = 1; });
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  std::fprintf(stderr, "decoding %s for %g s (Ctrl-C stops)...\n", request.interface->c_str(), duration_s);
  PumpOptions pump;
  pump.frame_wait_us = kLiveFrameWaitUs;
  pump.wall_clock_utime = WallClockUtime;
  pump.stop = [&] { return g_stop || std::chrono::steady_clock::now() >= end; };
  if (recorder) pump.on_frame = [&](const Frame& f) { recorder->Write(f); };
  PumpFrames(source, assembler, [&](const Scan& s, int64_t) { scans.Take(s); }, pump);
  std::vector<Scan> in_progress;  // stopped by time or Ctrl-C: the scan begun is still counted
  assembler.Flush(&in_progress);
  for (const Scan& s : in_progress) scans.Take(s);
  std::signal(SIGINT, SIG_DFL);
  if (request.send_start_frames)
    for (const Frame& f : profile.stop_frames) source.Send(f);
  if (recorder) recorder->Flush();
  const FrameSourceStats stats = source.Stats();
  std::printf("  %-18s %lld\n", "kernel_drops", static_cast<long long>(stats.kernel_drops));
  std::printf("  %-18s %lld\n", "read_errors", static_cast<long long>(stats.read_errors));
  return stats;
}

void PrintDecodeReport(const DecodeRequest& request, const SensorProfile& profile, const ScanAssembler& assembler,
                       const DecodedScans& scans, const CandumpLogSource* log, const FrameSourceStats& source_stats) {
  const BadFrameCounters& c = assembler.counters();
  std::printf("decoded %s with profile %s (%d taxels x %d axes, %d frames per scan)\n",
              request.log_path.c_str(), profile.name.c_str(), profile.taxel_count, profile.axes,
              profile.layout.frame_count);
  if (log) {
    std::printf("  %-18s %lld\n", "lines", static_cast<long long>(log->reader().lines_read()));
    std::printf("  %-18s %lld\n", "bad_lines", static_cast<long long>(log->reader().bad_line_count()));
  }
  std::printf("  %-18s %lld (%lld complete, %lld partial)\n", "scans", static_cast<long long>(scans.total()),
              static_cast<long long>(c.scans_complete), static_cast<long long>(c.scans_partial));
  if (assembler.tared())
    std::printf("  %-18s from %ld quiet scans\n", "tare", request.tare_scans);
  else if (request.tare_scans > 0)
    std::printf("  %-18s not reached (%ld quiet scans never seen)\n", "tare", request.tare_scans);
  std::printf("frames and scans:\n%s", FormatCounters(c).c_str());
  if (source_stats.error_frames > 0)
    std::printf("error frames: bus_off %lld, error_passive %lld, error_warning %lld, controller_overflow %lld, "
                "restarted %lld, other %lld\n",
                static_cast<long long>(source_stats.bus_off), static_cast<long long>(source_stats.error_passive),
                static_cast<long long>(source_stats.error_warning),
                static_cast<long long>(source_stats.controller_overflow),
                static_cast<long long>(source_stats.restarted), static_cast<long long>(source_stats.other_errors));
  if (log && !log->reader().bad_lines().empty()) {
    std::printf("bad lines (first %zu):\n", log->reader().bad_lines().size());
    for (const BadLine& b : log->reader().bad_lines())
      std::printf("  %s:%lld: %s: %s\n", request.log_path.c_str(), static_cast<long long>(b.line_number),
                  b.reason.c_str(), Printable(b.text).c_str());
  }
  if (scans.total() > 0) std::printf("%s", scans.taxel_health().Report().c_str());
  if (scans.wrote_csv()) std::printf("wrote %s\n", request.csv_path->c_str());
}

// The chosen scan as OUT.csv and, through tools/plot_taxels.py, OUT (PNG).
void DrawHeatmap(const DecodeRequest& request, const SensorProfile& profile, const DecodedScans& scans) {
  const Scan* chosen = scans.chosen();
  if (!chosen) {
    std::fprintf(stderr, "no scan %ld to draw\n", request.heatmap_scan);
    return;
  }
  const std::string& png = *request.heatmap_png;
  const std::string taxel_csv = png + ".csv";
  WriteTaxelCsv(profile, *chosen, taxel_csv, scans.chosen_health());
  std::printf("wrote %s (scan %lld)\n", taxel_csv.c_str(), static_cast<long long>(chosen->sequence));
  char when[96];
  std::snprintf(when, sizeof when, "\nt = %.3f s after the first scan%s", (chosen->utime - scans.first_utime()) * 1e-6,
                request.heatmap_scan < 0 ? " (peak pressure)" : "");
  const std::string title = profile.name + " scan " + std::to_string(chosen->sequence) + when;
  char width_mm[32], height_mm[32];
  std::snprintf(width_mm, sizeof width_mm, "%g", profile.taxel_width_mm);
  std::snprintf(height_mm, sizeof height_mm, "%g", profile.taxel_height_mm);
  const PlotResult plot =
      RunPythonScript("plot_taxels.py", {taxel_csv, png, "--title", title, "--size-mm", width_mm, height_mm});
  if (plot.ok)
    std::printf("wrote %s\n", png.c_str());
  else
    std::fprintf(stderr, "heatmap PNG not drawn: %s (the CSV is there)\n", plot.message.c_str());
}

int RunDecode(int argc, char** argv) {
  ArgParser args("sedbridge decode",
                 "Decodes a candump -l log of a tactile sensor into scans: one CSV row per scan\n"
                 "(scan,utime,complete, then one column per taxel axis in Pa: t<i>_x_Pa, t<i>_y_Pa\n"
                 "for shear, t<i>_z_Pa for normal pressure; empty where the taxel is invalid).\n"
                 "Prints counts of frames, scans and every kind of bad line or frame. A bad line\n"
                 "never stops the decode; it is reported with its line number. With --interface it\n"
                 "reads a live SocketCAN bus instead (kernel filters from the profile, error frames,\n"
                 "kernel time stamps) for --duration-s seconds or until Ctrl-C. Taxel health, as the\n"
                 "bridge judges it (the profile's taxel_health): each taxel masked, why (stuck high,\n"
                 "dead, frozen) and from when to when.");
  DeclareDecodeArgs(args);
  if (!args.Parse(argc, argv)) return 0;
  const SensorProfile profile = LoadNamedSensorProfile(args.Get("profile"));
  const DecodeRequest request = ReadDecodeRequest(args);
  DecodedScans scans(profile, request);
  AssemblerOptions options;
  options.tare_scans = static_cast<int>(request.tare_scans);
  ScanAssembler assembler(profile, options);

  std::unique_ptr<CandumpLogSource> log;
  FrameSourceStats source_stats;
  if (request.log_arg) {
    log = DecodeLog(request, assembler, scans);
    source_stats = log->Stats();
  } else {
    source_stats = DecodeInterface(args, request, profile, assembler, scans);
  }
  PrintDecodeReport(request, profile, assembler, scans, log.get(), source_stats);
  if (request.heatmap_png) DrawHeatmap(request, profile, scans);
  return scans.total() > 0 ? 0 : 1;
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(decode, "decode", "decode a candump log of a tactile sensor into scans (CSV, heatmap)",
                  &sedbridge::app::RunDecode);
