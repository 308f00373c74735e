// sedbridge decode: candump log -> scans (CSV), with counts of every bad line and frame.

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "app/arg_parser.h"
#include "app/command.h"
#include "common/wall_clock.h"
#include "sensors/candump_log.h"
#include "sensors/scan_assembler.h"
#include "sensors/scan_csv.h"
#include "sensors/socketcan_source.h"
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

int RunDecode(int argc, char** argv) {
  ArgParser args("sedbridge decode",
                 "Decodes a candump -l log of a tactile sensor into scans: one CSV row per scan\n"
                 "(scan,utime,complete, then one column per taxel axis in Pa: t<i>_x_Pa, t<i>_y_Pa\n"
                 "for shear, t<i>_z_Pa for normal pressure; empty where the taxel is invalid).\n"
                 "Prints counts of frames, scans and every kind of bad line or frame. A bad line\n"
                 "never stops the decode; it is reported with its line number. With --interface it\n"
                 "reads a live SocketCAN bus instead (kernel filters from the profile, error frames,\n"
                 "kernel time stamps) for --duration-s seconds or until Ctrl-C.");
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
  if (!args.Parse(argc, argv)) return 0;

  const SensorProfile profile = LoadNamedSensorProfile(args.Get("profile"));
  const auto log_arg = args.GetOptional("LOG");
  const auto interface = args.GetOptional("interface");
  if (log_arg.has_value() == interface.has_value())
    throw UsageError("give either a LOG file or --interface (see sedbridge decode --help)");
  if (!interface && (args.Has("start") || args.Has("record")))
    throw UsageError("--start and --record need --interface");
  const std::string log_path = log_arg ? *log_arg : "socketcan:" + *interface;
  std::ifstream file;
  std::istream* in = &std::cin;
  if (log_arg && *log_arg != "-") {
    file.open(*log_arg);
    if (!file) throw std::runtime_error("cannot open " + *log_arg);
    in = &file;
  }
  std::ofstream csv;
  if (auto path = args.GetOptional("csv")) {
    csv.open(*path);
    if (!csv) throw std::runtime_error("cannot write " + *path);
    csv << ScanCsvHeader(profile);
  }
  const long tare_scans = args.GetInt("tare-scans");
  const long max_bad_lines = args.GetInt("show-bad-lines");
  if (tare_scans < 0 || max_bad_lines < 0) throw UsageError("--tare-scans and --show-bad-lines must be >= 0");
  const auto heatmap_png = args.GetOptional("heatmap-png");
  const long heatmap_scan = args.Has("heatmap-scan") ? args.GetInt("heatmap-scan") : -1;

  AssemblerOptions options;
  options.tare_scans = static_cast<int>(tare_scans);
  ScanAssembler assembler(profile, options);
  CandumpLogReader reader(*in, log_path, static_cast<size_t>(max_bad_lines));
  FrameSourceStats source_stats;
  std::vector<Scan> scans;
  Scan chosen;
  bool have_chosen = false;
  double chosen_peak = -1;
  int64_t scan_total = 0;
  int64_t first_scan_utime = -1;  // heatmap title: time since the first scan, not a raw utime
  const bool tty = isatty(fileno(stderr));
  Frame frame;
  std::string row;
  auto consume = [&]() {
    for (const Scan& s : scans) {
      if (first_scan_utime < 0) first_scan_utime = s.utime;
      if (csv.is_open()) {
        row.clear();
        AppendScanCsvRow(s, &row);
        csv << row;
      }
      if (heatmap_png) {
        if (heatmap_scan >= 0) {
          if (s.sequence == heatmap_scan) chosen = s, have_chosen = true;
        } else {
          double peak = 0;
          for (int i = 0; i < s.num_taxels; ++i)
            if (s.valid[i]) peak = std::max(peak, s.pressure_Pa[i]);
          if (peak > chosen_peak) chosen = s, chosen_peak = peak, have_chosen = true;
        }
      }
    }
    scan_total += static_cast<int64_t>(scans.size());
    scans.clear();
  };
  if (!interface) {
    while (reader.Next(&frame)) {
      ++source_stats.frames;
      if (frame.error) CountErrorFrame(frame, &source_stats);
      assembler.Push(frame, &scans);
      if (!scans.empty()) consume();
      if ((reader.lines_read() & ((1 << 20) - 1)) == 0)  // progress on long logs
        std::fprintf(stderr, tty ? "\r  %lld lines, %lld scans..." : "  %lld lines, %lld scans...\n",
                     static_cast<long long>(reader.lines_read()), static_cast<long long>(scan_total));
    }
    if (tty && reader.lines_read() >= (1 << 20)) std::fprintf(stderr, "\n");
  } else {
    const double duration_s = args.GetDouble("duration-s");
    if (!(duration_s > 0)) throw UsageError("--duration-s must be > 0");
    SocketCanSource source(OptionsForProfile(profile, *interface));
    std::ofstream record_file;
    std::unique_ptr<CandumpLogWriter> recorder;
    if (auto path = args.GetOptional("record")) {
      record_file.open(*path);
      if (!record_file) throw std::runtime_error("cannot write " + *path);
      recorder = std::make_unique<CandumpLogWriter>(record_file);
    }
    if (args.GetFlag("start"))
      for (const Frame& f : profile.start_frames)
        if (!source.Send(f)) std::fprintf(stderr, "warning: could not send start frame %s\n", FormatCandumpLine(f).c_str());
    g_stop = 0;
    std::signal(SIGINT, [](int) { g_stop = 1; });
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
    std::fprintf(stderr, "decoding %s for %g s (Ctrl-C stops)...\n", interface->c_str(), duration_s);
    while (!g_stop && !source.Done() && std::chrono::steady_clock::now() < end) {
      if (auto f = source.Next(20000)) {
        if (recorder) recorder->Write(*f);
        assembler.Push(*f, &scans);
      } else {
        assembler.Poll(WallClockUtime(), &scans);
      }
      if (!scans.empty()) consume();
    }
    std::signal(SIGINT, SIG_DFL);
    if (args.GetFlag("start"))
      for (const Frame& f : profile.stop_frames) source.Send(f);
    if (recorder) recorder->Flush();
    source_stats = source.Stats();
    std::printf("  %-18s %lld\n", "kernel_drops", static_cast<long long>(source_stats.kernel_drops));
    std::printf("  %-18s %lld\n", "read_errors", static_cast<long long>(source_stats.read_errors));
  }
  assembler.Flush(&scans);
  consume();

  const BadFrameCounters& c = assembler.counters();
  std::printf("decoded %s with profile %s (%d taxels x %d axes, %d frames per scan)\n",
              log_path.c_str(), profile.name.c_str(), profile.taxel_count, profile.axes,
              profile.layout.frame_count);
  if (!interface) {
    std::printf("  %-18s %lld\n", "lines", static_cast<long long>(reader.lines_read()));
    std::printf("  %-18s %lld\n", "bad_lines", static_cast<long long>(reader.bad_line_count()));
  }
  std::printf("  %-18s %lld (%lld complete, %lld partial)\n", "scans", static_cast<long long>(scan_total),
              static_cast<long long>(c.scans_complete), static_cast<long long>(c.scans_partial));
  if (assembler.tared())
    std::printf("  %-18s from %ld quiet scans\n", "tare", tare_scans);
  else if (tare_scans > 0)
    std::printf("  %-18s not reached (%ld quiet scans never seen)\n", "tare", tare_scans);
  std::printf("frames and scans:\n%s", FormatCounters(c).c_str());
  if (source_stats.error_frames > 0)
    std::printf("error frames: bus_off %lld, error_passive %lld, error_warning %lld, controller_overflow %lld, "
                "restarted %lld, other %lld\n",
                static_cast<long long>(source_stats.bus_off), static_cast<long long>(source_stats.error_passive),
                static_cast<long long>(source_stats.error_warning),
                static_cast<long long>(source_stats.controller_overflow),
                static_cast<long long>(source_stats.restarted), static_cast<long long>(source_stats.other_errors));
  if (!reader.bad_lines().empty()) {
    std::printf("bad lines (first %zu):\n", reader.bad_lines().size());
    for (const BadLine& b : reader.bad_lines())
      std::printf("  %s:%lld: %s: %s\n", log_path.c_str(), static_cast<long long>(b.line_number),
                  b.reason.c_str(), Printable(b.text).c_str());
  }
  if (csv.is_open()) std::printf("wrote %s\n", args.Get("csv").c_str());

  if (heatmap_png) {
    if (!have_chosen) {
      std::fprintf(stderr, "no scan %ld to draw\n", heatmap_scan);
    } else {
      const std::string taxel_csv = *heatmap_png + ".csv";
      WriteTaxelCsv(profile, chosen, taxel_csv);
      std::printf("wrote %s (scan %lld)\n", taxel_csv.c_str(), static_cast<long long>(chosen.sequence));
      char when[96];
      std::snprintf(when, sizeof when, "\nt = %.3f s after the first scan%s", (chosen.utime - first_scan_utime) * 1e-6,
                    heatmap_scan < 0 ? " (peak pressure)" : "");
      const std::string title = profile.name + " scan " + std::to_string(chosen.sequence) + when;
      const PlotResult plot = PlotTaxelHeatmap(profile, taxel_csv, *heatmap_png, title);
      if (plot.ok)
        std::printf("%s\n", plot.message.c_str());
      else
        std::fprintf(stderr, "heatmap PNG not drawn: %s (the CSV is there)\n", plot.message.c_str());
    }
  }
  return scan_total > 0 ? 0 : 1;
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(decode, "decode", "decode a candump log of a tactile sensor into scans (CSV, heatmap)",
                  &sedbridge::app::RunDecode);
