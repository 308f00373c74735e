#include "bridge/replay.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "bridge/display_requests.h"
#include "bridge/finger_workers.h"
#include "bridge/leader_model_cache.h"
#include "bridge/make_fe_step.h"
#include "bridge/sa1_rate_at_peak.h"
#include "lcm/contact_estimate_message.h"
#include "lcm/taxel_health_message.h"
#include "common/thread_cpu_time.h"
#include "common/wall_clock.h"
#include "scene/vtu_writer.h"
#include "sensors/frame_pump.h"
#include "sensors/frame_router.h"
#include "sensors/scan_assembler.h"

namespace sedbridge::bridge {
namespace {

// A progress line on stderr every this many scans (ReplayOptions::progress).
constexpr size_t kProgressEveryScans = 1000;
// A command within this fraction of the ceiling counts as at the ceiling [-] (float
// round-off of the published value).
constexpr double kAtCeilingFraction = 1 - 1e-6;

}  // namespace

void WriteSummaryCsv(const std::string& path, const std::vector<ReplayRow>& rows) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << "utime,total_force_N,applied_force_N,max_sed_Pa,max_command,latency_ms,stepped,invalid_taxels\n";
  char buf[256];
  for (const ReplayRow& r : rows) {
    std::snprintf(buf, sizeof buf, "%lld,%.6g,%.6g,%.6g,%.6g,%.4f,%d,%d\n", static_cast<long long>(r.utime),
                  r.total_force_N, r.applied_force_N, r.max_sed_Pa, r.max_command, r.latency_ms, r.stepped ? 1 : 0,
                  r.invalid_taxels);
    f << buf;
  }
  if (!f) throw std::runtime_error("write failed: " + path);
}

void WriteStageCsv(const std::string& path, const std::vector<ReplayRow>& rows) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << "utime";
  for (int i = 0; i < kNumStages; ++i) f << ',' << ToString(static_cast<Stage>(i)) << "_ms";
  f << ",scan_cpu_ms\n";
  char buf[32];
  for (const ReplayRow& r : rows) {
    f << r.utime;
    for (double ms : r.stage_ms.ms) {
      std::snprintf(buf, sizeof buf, ",%.4f", ms);
      f << buf;
    }
    std::snprintf(buf, sizeof buf, ",%.4f\n", r.cpu_ms);
    f << buf;
  }
  if (!f) throw std::runtime_error("write failed: " + path);
}

namespace {

// Where the pipeline publishes: options.lcm_url, and the LCM log in the out folder (made here).
lcm_io::LcmSettings ReplayLcmSettings(const BridgeConfig& config, const ReplayOptions& options) {
  lcm_io::LcmSettings lcm = config.lcm;
  lcm.url = options.lcm_url;
  lcm.log_path.clear();
  if (!options.out_dir.empty()) {
    std::filesystem::create_directories(options.out_dir);
    if (options.write_lcm_log) lcm.log_path = (std::filesystem::path(options.out_dir) / "bridge.lcmlog").string();
  }
  return lcm;
}

sensors::AssemblerOptions ReplayAssemblerOptions(const BridgeConfig& config, const ReplayOptions& options) {
  sensors::AssemblerOptions assembler_options;
  assembler_options.tare_scans = config.tare_scans;
  assembler_options.interface = options.can_interface;
  return assembler_options;
}

ReplayRow RowOf(const sensors::Scan& scan, const ScanOutcome& o) {
  ReplayRow row;
  row.utime = scan.utime;
  row.total_force_N = o.total_force_N;
  row.applied_force_N = o.applied_force_N;
  row.max_sed_Pa = o.max_sed_Pa;
  row.max_command = o.max_command;
  row.latency_ms = o.latency_us * 1e-3;
  row.stepped = o.stepped;
  row.invalid_taxels = o.invalid_taxels;
  row.stage_ms = o.stage_ms;
  return row;
}

// What the scan of peak SED left, for the peak_*.csv files.
struct PeakSnapshot {
  double sed_Pa = -1;
  display::SedField field;
  display::DisplayCommand command;
  TaxelValues values;
  std::vector<int8_t> taxel_health;  // lcm_io::TaxelHealthCode per taxel at the peak scan
  bool have_contact = false;
  lcmt_contact_estimate contact{};

  void Take(BridgePipeline& pipeline, double max_sed_Pa) {
    sed_Pa = max_sed_Pa;
    field = pipeline.last_field();
    command = pipeline.last_command();
    values = pipeline.last_values();
    const sensors::TaxelHealth& health = pipeline.taxel_health();
    taxel_health.assign(static_cast<size_t>(health.taxel_count()), 0);
    for (int k = 0; k < health.taxel_count(); ++k)
      taxel_health[static_cast<size_t>(k)] = static_cast<int8_t>(lcm_io::TaxelHealthCodeOf(health, k));
    if (const contact::ContactReport* m = pipeline.fe().contact_report()) contact = lcm_io::ToLcm(*m), have_contact = true;
  }
};

// Optional VTU frames of whatever the FE step can show (FeStep::Frame), every
// options.vtu_every-th stepped scan, listed in frames.pvd.
class VtuFrames {
 public:
  VtuFrames(FeStep& fe, const ReplayOptions& options) : fe_(fe), out_dir_(options.out_dir), every_(options.vtu_every) {
    const bool has_frames = fe_.Frame(&frame_);
    if (every_ > 0 && !has_frames)
      std::fprintf(stderr, "note: --vtu-every: this FE step keeps no full displacement field, no frames written\n");
    if (every_ > 0 && has_frames && !out_dir_.empty())
      pvd_ = std::make_unique<scene::PvdCollection>((std::filesystem::path(out_dir_) / "frames.pvd").string(),
                                                    "time since the first scan [s] (log time)");
  }

  /// After row `index` (utime, applied force) of a run whose first scan is at first_utime.
  void AfterScan(bool stepped, size_t index, int64_t utime, int64_t first_utime, double applied_force_N) {
    if (!pvd_ || !stepped || index % size_t(every_) != 0) return;
    if (!fe_.Frame(&frame_)) return;
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06zu.vtu", index);
    const double t_s = (utime - first_utime) * 1e-6;
    scene::WriteVtu((std::filesystem::path(out_dir_) / name).string(), *frame_.mesh, frame_.positions_m,
                    frame_.point_fields, {},
                    {{"time_s", t_s}, {"scan", double(index)}, {"applied_force_N", applied_force_N}});
    pvd_->Add(t_s, name);
  }

 private:
  FeStep& fe_;
  std::string out_dir_;
  int every_;
  FeFrame frame_;
  std::unique_ptr<scene::PvdCollection> pvd_;
};

// The run's counters, latency and stage medians from the pipeline, the assembler and the
// source, once the display is shut down.
void CollectCounters(BridgePipeline& pipeline, const sensors::ScanAssembler& assembler,
                     const sensors::FrameSource& source, ReplayResult* result) {
  result->counters = pipeline.counters();
  result->latency = pipeline.latency().Run();
  result->stage_p50_ms = pipeline.RunStageMedians_ms();
  result->bad_frames = assembler.counters();
  result->source_stats = source.Stats();
  result->published = pipeline.display().publisher().published();
  result->publish_errors = pipeline.display().publisher().publish_errors();
}

// Saturation in the SED -> command mapping is silent (the limiter's `clamped` only flags
// requests above its maximum), so count it here for the summary and the plots.
void CountCeiling(const display::DisplayProfile& dp, const display::DisplayCommand& peak_command,
                  ReplayResult* result) {
  result->display_actuators = static_cast<int>(dp.size());
  // The inverse renderer's bound is the safety maximum; the curve's is its saturation too.
  const bool curve = !result->inverse_rendering;
  result->command_ceiling = curve ? std::min(dp.mapping.saturation, dp.safety.max) : dp.safety.max;
  result->ceiling_is_mapping = curve && dp.mapping.saturation <= dp.safety.max;
  const double at = result->command_ceiling * kAtCeilingFraction;
  for (double v : peak_command.value) result->peak_actuators_at_ceiling += v >= at ? 1 : 0;
  for (const ReplayRow& r : result->rows) result->scans_at_ceiling += r.max_command >= at ? 1 : 0;
}

// The reconstructed contact at the peak, with its Hertz contact size on the sensor (sphere:
// radius; rod: half-width) for the plot.
void WritePeakContactCsv(const std::string& path, const lcmt_contact_estimate& m,
                         const sensors::SensorProfile& profile) {
  const bool sphere = m.shape == 1 || m.shape == 4;
  auto half_width_mm = [&](double force_N, double radius_mm) {
    if (!profile.has_forward_model || !(force_N > 0) || !(sphere || m.shape == 2)) return 0.0;
    const double E = profile.forward_model.contact_modulus_kPa * 1e-3;  // N/mm^2
    return sphere ? std::cbrt(3.0 * force_N * radius_mm / (4.0 * E))
                  : std::sqrt(4.0 * force_N / profile.forward_model.pad_size_mm * radius_mm / (3.14159265358979 * E));
  };
  static const char* const kShapes[] = {"none", "sphere", "cylinder", "flat", "two_spheres"};
  std::ofstream con(path);
  con << "shape,x_mm,y_mm,radius_mm,yaw_deg,normal_force_N,shear_x_N,shear_y_N,residual_rms_sigma,fallback,"
         "contact_half_width_mm,x2_mm,y2_mm,radius2_mm,normal_force2_N,contact2_half_width_mm,length_mm\n";
  con << kShapes[std::clamp<int>(m.shape, 0, 4)] << ',' << m.x_mm << ',' << m.y_mm << ',' << m.radius_mm << ','
      << m.yaw_deg << ',' << m.normal_force_N << ',' << m.shear_x_N << ',' << m.shear_y_N << ','
      << m.residual_rms_sigma << ',' << int(m.fallback) << ',' << half_width_mm(m.normal_force_N, m.radius_mm) << ','
      << m.x2_mm << ',' << m.y2_mm << ',' << m.radius2_mm << ',' << m.normal_force2_N << ','
      << half_width_mm(m.normal_force2_N, m.radius2_mm) << ',' << m.length_mm << '\n';
}

// The files of ReplayOptions::out_dir (replay.h) but bridge.lcmlog and the VTU frames.
void WriteReplayFiles(const std::filesystem::path& dir, const ReplayResult& result, const PeakSnapshot& peak,
                      const display::DisplayProfile& dp, const BridgeConfig& config,
                      const sensors::SensorProfile& profile) {
  WriteSummaryCsv((dir / "summary.csv").string(), result.rows);
  // Written by FinishInverse for the inverse rendering only, by FinishSa1Estimate for an
  // electrotactile display only: no stale one from an earlier run.
  std::filesystem::remove(dir / "peak_display_sed.csv");
  std::filesystem::remove(dir / "peak_sa1_rate_estimate.csv");
  WriteStageCsv((dir / "stage_ms.csv").string(), result.rows);
  std::ofstream sed((dir / "peak_merkel_sed.csv").string());
  sed << "x_mm,y_mm,z_mm,sed_Pa\n";
  for (size_t k = 0; k < peak.field.sed_Pa.size(); ++k)
    sed << peak.field.x_mm[k] << ',' << peak.field.y_mm[k] << ',' << peak.field.z_mm[k] << ','
        << peak.field.sed_Pa[k] << '\n';
  std::ofstream cmd((dir / "peak_command.csv").string());
  cmd << "actuator,x_mm,y_mm,value\n";
  for (size_t k = 0; k < dp.x_mm.size(); ++k)
    cmd << k << ',' << dp.x_mm[k] << ',' << dp.y_mm[k] << ','
        << (k < peak.command.value.size() ? peak.command.value[k] : 0.0) << '\n';
  std::ofstream tax((dir / "peak_taxels.csv").string());
  // health: taxel health at the peak scan (lcm_io::TaxelHealthName; a masked taxel's
  // pressure is not its reading), for tools/plot_bridge.py to mark.
  tax << "taxel,x_mm,y_mm,pressure_Pa,health\n";
  const PadRegistration reg(profile.taxels, config.registration);
  for (size_t k = 0; k < peak.values.pressure_Pa.size() && k < profile.taxels.size(); ++k) {
    const Eigen::Vector2d p = reg.ToPad({profile.taxels[k].x_mm, profile.taxels[k].y_mm});
    tax << k << ',' << p.x() << ',' << p.y() << ',' << peak.values.pressure_Pa[k] << ','
        << lcm_io::TaxelHealthName(k < peak.taxel_health.size() ? peak.taxel_health[k] : 0) << '\n';
  }
  if (peak.have_contact) WritePeakContactCsv((dir / "peak_contact.csv").string(), peak.contact, profile);
}

// Inverse rendering: the renderer's times, and what the display delivers at the peak scan by
// the full FE (peak_display_sed.csv in `out_dir` unless empty) against what was asked.
void FinishInverse(InverseDisplayRequests& inverse, const PeakSnapshot& peak, const std::string& out_dir,
                   ReplayResult* result) {
  result->render_ms = inverse.render_times().Run();
  result->render_cpu_ms = inverse.render_cpu_times().Run();
  result->render_not_converged = inverse.not_converged();
  const InverseDisplayRequests::EvaluationCounts evaluations = inverse.evaluation_counts();
  result->render_evaluations_median = evaluations.median;
  result->render_evaluations_p99 = evaluations.p99;
  result->render_evaluations_max = evaluations.max;
  if (peak.sed_Pa < 0) {
    result->display_fidelity_error = "no stepped scan";
    return;
  }
  Eigen::VectorXd delivered;
  if (!inverse.Deliver(peak.command.value, &delivered)) {
    result->display_fidelity_error = "the full FE of the peak commands failed: " + inverse.error();
    return;
  }
  const display::SedField& f = peak.field;
  Eigen::Matrix3Xd pad_mm(3, Eigen::Index(f.size()));
  for (size_t k = 0; k < f.size(); ++k) pad_mm.col(Eigen::Index(k)) << f.x_mm[k], f.y_mm[k], f.z_mm[k];
  const Eigen::VectorXd asked = Eigen::Map<const Eigen::VectorXd>(f.sed_Pa.data(), Eigen::Index(f.size()));
  result->display_fidelity = CompareDeliveredSed(pad_mm, delivered, asked);
  result->have_display_fidelity = true;
  if (out_dir.empty()) return;
  const std::string path = (std::filesystem::path(out_dir) / "peak_display_sed.csv").string();
  std::ofstream out(path);
  out << "vertex,x_mm,y_mm,z_mm,sed_Pa\n";
  for (size_t k = 0; k < f.size(); ++k)
    out << k << ',' << f.x_mm[k] << ',' << f.y_mm[k] << ',' << f.z_mm[k] << ',' << delivered[Eigen::Index(k)] << '\n';
  if (!out) throw std::runtime_error("write failed: " + path);
}

// Electrotactile (no mechanical load on the finger): the SA1 rate ESTIMATE at each electrode
// from the SED asked at the peak scan, what its commands are read against
// (peak_sa1_rate_estimate.csv in `out_dir` unless empty).
void FinishSa1Estimate(const display::DisplayProfile& dp, const PeakSnapshot& peak, const std::string& out_dir,
                       ReplayResult* result) {
  if (peak.sed_Pa < 0) return;
  const Sa1RateAtSites e = EstimateSa1RateAtSites(dp, peak.field);
  if (e.peak_site < 0) return;
  result->have_sa1_estimate = true;
  result->sa1_peak_electrode = e.peak_site;
  result->sa1_peak_rate_estimate_Hz = e.rate_Hz[size_t(e.peak_site)];
  result->sa1_peak_site_sed_Pa = e.sed_at_site_Pa[size_t(e.peak_site)];
  if (!out_dir.empty())
    WriteSa1RateEstimateCsv((std::filesystem::path(out_dir) / "peak_sa1_rate_estimate.csv").string(), dp, e,
                            peak.command.value);
}

// One finger's replay: its pipeline, assembler, rows, peak and files (ReplayResult). The
// one-finger replay and the hand's run the same steps: build, Process each scan, Finish.
class FingerRun {
 public:
  FingerRun(const BridgeConfig& config, const sensors::SensorProfile& profile,
            const display::DisplayProfile& display_profile, std::unique_ptr<FeStep> fe,
            const sensors::FrameSource& source, const ReplayOptions& options,
            InverseRenderingCache* renderings = nullptr)
      : config_(config), profile_(profile), options_(options), source_(source) {
    using Clock = std::chrono::steady_clock;
    const auto t_setup = Clock::now();
    if (!fe) fe = MakeFeStep(config, profile, options.vtu_every > 0 && !options.out_dir.empty(), &display_profile);
    result_.fe_description = fe->Describe();
    requests_ = MakeDisplayRequests(config, display_profile, fe->merkel_rest_pad_mm(),
                                    [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); },
                                    renderings);
    result_.display_rendering = requests_.Describe();
    result_.inverse_rendering = bool(requests_.inverse);
    if (requests_.inverse) std::fprintf(stderr, "%s\n", result_.display_rendering.c_str());
    pipeline_ = std::make_unique<BridgePipeline>(config, profile, display_profile, std::move(fe),
                                                 ReplayLcmSettings(config, options), BridgePipeline::WallClock{},
                                                 requests_.source());
    if (auto inverse = requests_.inverse)
      pipeline_->SetPredictedSed([inverse](Eigen::VectorXd* sed, std::vector<double>* u) { inverse->PredictedSed(sed, u); });
    result_.display_unit = pipeline_->display().controller().profile().unit;
    assembler_ = std::make_unique<sensors::ScanAssembler>(profile, ReplayAssemblerOptions(config, options));
    result_.setup_s = std::chrono::duration<double>(Clock::now() - t_setup).count();
    if (options.on_start) options.on_start(*pipeline_);
    frames_ = std::make_unique<VtuFrames>(pipeline_->fe(), options);
  }

  /// One scan through the pipeline, its row, the peak snapshot and the optional VTU frame.
  void Process(const sensors::Scan& scan, int64_t receive_wall) {
    Process(scan, receive_wall, assembler_->counters(), source_.Stats());
  }
  /// The same with the sensor's counters as they were when the scan was emitted (a hand on
  /// several threads: the pump's thread owns the assembler and the source).
  void Process(const sensors::Scan& scan, int64_t receive_wall, const sensors::BadFrameCounters& counters,
               const sensors::FrameSourceStats& source_stats) {
    pipeline_->SetSensorCounters(counters, source_stats);
    const double cpu_start_ms = ThreadCpuTime_ms();
    const ScanOutcome o = pipeline_->ProcessScan(scan, scan.utime, receive_wall);
    const double cpu_ms = ThreadCpuTime_ms() - cpu_start_ms;
    last_utime_ = end_utime_ = scan.utime;
    last_scan_wall_ = receive_wall;
    result_.rows.push_back(RowOf(scan, o));
    result_.rows.back().cpu_ms = cpu_ms;
    const size_t index = result_.rows.size() - 1;
    if (o.stepped && o.max_sed_Pa > peak_.sed_Pa) {
      peak_.Take(*pipeline_, o.max_sed_Pa);
      result_.peak_index = static_cast<int>(index);
    }
    frames_->AfterScan(o.stepped, index, scan.utime, result_.rows.front().utime, result_.rows.back().applied_force_N);
    if (options_.on_scan) options_.on_scan(o, *pipeline_);
    if (options_.progress && result_.rows.size() % kProgressEveryScans == 0)
      std::fprintf(stderr, "  %zu scans (log time %.2f s)\n", result_.rows.size(),
                   (scan.utime - result_.rows.front().utime) * 1e-6);
  }

  /// Paced source silent at wall time `wall`: ticks the display in log time.
  void IdleTick(int64_t wall) {
    if (result_.rows.empty()) return;
    pipeline_->Tick(last_utime_ + static_cast<int64_t>((wall - last_scan_wall_) * options_.paced_speed));
    ++result_.idle_ticks;
  }
  /// Display tick at log time `utime` (a hand: this finger's sensor silent while another's
  /// speaks), with the sensor's counters then (a bus-off shows on its BRIDGE_STATUS).
  void Tick(int64_t utime, const sensors::BadFrameCounters& counters, const sensors::FrameSourceStats& source_stats) {
    pipeline_->SetSensorCounters(counters, source_stats);
    pipeline_->Tick(utime);
    end_utime_ = std::max(end_utime_, utime);
  }

  /// Zero the display without letting a second error out (an error is on its way).
  void ShutdownQuietly() {
    try {
      pipeline_->Shutdown(end_utime_);
    } catch (...) {
    }
  }

  /// After the source: display to zero, counters, files; the result.
  ReplayResult Finish(double wall_s, bool stopped_early) {
    result_.wall_s = wall_s;
    result_.stopped_early = stopped_early;
    pipeline_->SetSensorCounters(assembler_->counters(), source_.Stats());
    pipeline_->Shutdown(end_utime_);
    result_.fe_counters = pipeline_->fe().CountersLine();
    result_.taxel_health = pipeline_->taxel_health().Summary();
    if (options_.on_finish) options_.on_finish(*pipeline_);
    CollectCounters(*pipeline_, *assembler_, source_, &result_);
    const display::DisplayProfile& dp = pipeline_->display().controller().profile();
    CountCeiling(dp, peak_.command, &result_);
    if (!options_.out_dir.empty()) WriteReplayFiles(options_.out_dir, result_, peak_, dp, config_, profile_);
    if (requests_.inverse) FinishInverse(*requests_.inverse, peak_, options_.out_dir, &result_);
    if (dp.kind == display::DisplayKind::kElectrotactile) FinishSa1Estimate(dp, peak_, options_.out_dir, &result_);
    return std::move(result_);
  }

  sensors::ScanAssembler& assembler() { return *assembler_; }
  BridgePipeline& pipeline() { return *pipeline_; }

 private:
  BridgeConfig config_;
  sensors::SensorProfile profile_;
  ReplayOptions options_;
  const sensors::FrameSource& source_;
  ReplayResult result_;
  DisplayRequests requests_;
  std::unique_ptr<BridgePipeline> pipeline_;
  std::unique_ptr<sensors::ScanAssembler> assembler_;
  PeakSnapshot peak_;
  std::unique_ptr<VtuFrames> frames_;
  int64_t last_utime_ = 0;
  int64_t end_utime_ = 0;  // the last scan's or (a hand) tick's: the shutdown's time stamp
  int64_t last_scan_wall_ = WallClockUtime();
};

// The pump's options of a replay (paced or not, stop flag); on_idle is the caller's.
sensors::PumpOptions ReplayPumpOptions(const ReplayOptions& options) {
  const bool paced = options.paced_speed > 0;
  if (paced && options.idle_tick_period_us <= 0) throw std::invalid_argument("idle_tick_period_us must be > 0");
  sensors::PumpOptions pump;
  // Paced: wait at most one tick, so a pause in the log still ticks the watchdog.
  pump.frame_wait_us = paced ? options.idle_tick_period_us : -1;
  pump.wall_clock_utime = WallClockUtime;
  pump.poll_on_timeout = false;  // a log's gaps are the recording's, not a late scan
  if (options.stop) pump.stop = [&options] { return options.stop->load(); };
  return pump;
}

}  // namespace

ReplayResult RunReplay(const BridgeConfig& config, const sensors::SensorProfile& profile,
                       const display::DisplayProfile& display_profile, std::unique_ptr<FeStep> fe,
                       sensors::FrameSource& source, const ReplayOptions& options) {
  using Clock = std::chrono::steady_clock;
  FingerRun finger(config, profile, display_profile, std::move(fe), source, options);
  const auto t0 = Clock::now();
  sensors::PumpOptions pump = ReplayPumpOptions(options);
  if (options.paced_speed > 0) pump.on_idle = [&](int64_t wall) { finger.IdleTick(wall); };
  bool stopped = false;
  try {
    stopped = sensors::PumpFrames(source, finger.assembler(),
                                  [&](const sensors::Scan& scan, int64_t wall) { finger.Process(scan, wall); }, pump)
                  .stopped;
  } catch (...) {
    // Zero first, then let the error out (the log is closed when the pipeline goes). A
    // second error while shutting down must not replace the first.
    finger.ShutdownQuietly();
    throw;
  }
  return finger.Finish(std::chrono::duration<double>(Clock::now() - t0).count(), stopped);
}

namespace {

// When a hand's fingers get display ticks (kept by the pump's thread, whatever thread a finger
// runs on): a finger whose sensor is overdue (no scan for two of its scan periods) is ticked
// at its rates.tick_Hz, as `run` ticks a silent bus, so its watchdog ramps its display to
// zero. A finger whose scans come on time is not ticked: its outputs are its replay alone's.
class SilentFingerTicks {
 public:
  explicit SilentFingerTicks(const std::vector<HandFinger>& fingers) : last_scan_(fingers.size(), -1), last_activity_(fingers.size(), -1) {
    for (const HandFinger& f : fingers) {
      tick_period_us_.push_back(static_cast<int64_t>(1e6 / f.config.tick_Hz));
      overdue_us_.push_back(static_cast<int64_t>(2e6 / f.profile.scan_rate_Hz));
    }
  }
  /// Finger `speaking` has a scan at `utime`: calls tick(j) for every finger j to tick first.
  template <typename Tick>
  void BeforeScan(int speaking, int64_t utime, const Tick& tick) {
    for (size_t j = 0; j < last_scan_.size(); ++j) {
      if (int(j) == speaking || last_scan_[j] < 0) continue;
      if (utime - last_scan_[j] > overdue_us_[j] && utime - last_activity_[j] >= tick_period_us_[j]) {
        last_activity_[j] = utime;
        tick(int(j));
      }
    }
    last_scan_[size_t(speaking)] = last_activity_[size_t(speaking)] = utime;
  }

 private:
  std::vector<int64_t> last_scan_, last_activity_, tick_period_us_, overdue_us_;
};

// Every finger's leader model first (BuildHandFeSteps), with the cache's counts in the result.
void BuildFeSteps(std::vector<HandFinger>& fingers, const ReplayOptions& options, HandReplayResult* result) {
  LeaderModelCache leaders;
  BuildHandFeSteps(fingers, options.vtu_every > 0 && !options.out_dir.empty(), &leaders);
  result->leader_models_loaded = leaders.models_loaded();
  result->leader_models_shared = leaders.models_shared();
  result->leader_operators_shared = leaders.operators_shared();
  result->fallbacks_shared = leaders.fallbacks_shared();
}

}  // namespace

void BuildHandFeSteps(std::vector<HandFinger>& fingers, bool full_field, LeaderModelCache* leaders) {
  for (HandFinger& f : fingers) {
    if (f.fe) continue;
    try {
      f.fe = MakeFeStep(f.config, f.profile, full_field, &f.display_profile, leaders);
    } catch (const std::exception& e) {
      throw std::runtime_error("finger '" + f.name + "': leader model '" + f.config.model + "': " + e.what());
    }
  }
}

HandReplayResult RunHandReplay(std::vector<HandFinger> fingers, sensors::FrameSource& source,
                               const ReplayOptions& options) {
  using Clock = std::chrono::steady_clock;
  HandReplayResult result;
  sensors::FrameRouter router;
  for (size_t i = 0; i < fingers.size(); ++i)
    router.Claim(int(i), fingers[i].name, fingers[i].config.can_interface, fingers[i].profile);
  BuildFeSteps(fingers, options, &result);
  std::vector<std::unique_ptr<FingerRun>> runs;
  std::vector<sensors::ScanAssembler*> assemblers;
  InverseRenderingCache renderings;  // one precompute a (leader model, display), shared
  auto zero_all = [&] {
    for (auto& run : runs) run->ShutdownQuietly();
  };
  try {
    // A finger whose display rendering fails to build stops the start-up: the ones already
    // built are zeroed.
    for (HandFinger& f : fingers) {
      ReplayOptions own = options;
      own.can_interface = f.config.can_interface;
      if (!options.out_dir.empty()) own.out_dir = (std::filesystem::path(options.out_dir) / f.name).string();
      runs.push_back(std::make_unique<FingerRun>(f.config, f.profile, f.display_profile, std::move(f.fe), source, own,
                                                 &renderings));
      assemblers.push_back(&runs.back()->assembler());
      result.names.push_back(f.name);
    }
  } catch (...) {
    zero_all();
    throw;
  }
  const auto t0 = Clock::now();
  FingerWorkers workers(int(runs.size()), options.finger_threads);
  SilentFingerTicks ticks(fingers);
  sensors::PumpOptions pump = ReplayPumpOptions(options);
  if (options.paced_speed > 0)
    pump.on_idle = [&](int64_t wall) {
      for (size_t j = 0; j < runs.size(); ++j) workers.Post(int(j), [run = runs[j].get(), wall] { run->IdleTick(wall); });
    };
  sensors::PumpResult pumped;
  try {
    pumped = sensors::PumpRoutedFrames(
        source, router, assemblers,
        [&](int index, sensors::Scan& scan, int64_t wall) {
          // The counters are read here, on the pump's thread, which owns assemblers and source.
          ticks.BeforeScan(index, scan.utime, [&](int j) {
            workers.Post(j, [run = runs[size_t(j)].get(), utime = scan.utime, c = assemblers[size_t(j)]->counters(),
                             st = source.Stats()] { run->Tick(utime, c, st); });
          });
          workers.Post(index, [run = runs[size_t(index)].get(), s = std::move(scan), wall,
                               c = assemblers[size_t(index)]->counters(),
                               st = source.Stats()] { run->Process(s, wall, c, st); });
        },
        pump);
    workers.Finish();
  } catch (...) {
    try {
      workers.Finish();
    } catch (...) {
    }
    zero_all();
    throw;
  }
  result.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  result.frames = pumped.frames;
  result.stopped_early = pumped.stopped;
  result.unclaimed_frames = router.unclaimed();
  result.finger_threads = workers.threads();
  result.display_renderings_built = renderings.built();
  result.display_renderings_shared = renderings.shared();
  try {
    for (auto& run : runs) result.fingers.push_back(run->Finish(result.wall_s, pumped.stopped));
  } catch (...) {
    zero_all();
    throw;
  }
  return result;
}

}  // namespace sedbridge::bridge
