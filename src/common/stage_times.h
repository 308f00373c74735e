#pragma once
// Where the time of one scan (or one FE step) went, stage by stage (MuJoCo's mjData.timer
// idea): each stage adds its wall time, the step and scan reports carry the result, and
// BRIDGE_STATUS, the replay summary and the benchmarks print it. Header-only: every stage
// folder (fem, bridge, display) may use it.

#include <array>
#include <chrono>
#include <cstdio>
#include <string>

#include "common/enum_names.h"

namespace sedbridge {

/// The stages of the data path, in order. A path uses the ones it has (the reduced FE step
/// has no assembly; the contact step reconstructs and presses instead).
enum class Stage {
  kConditioning,       ///< scan -> taxel values (registration, invalid taxels, NaN guard)
  kBoundaryCondition,  ///< taxel values -> nodal tractions
  kAssembly,           ///< force terms and system matrix
  kSolve,              ///< factorization and linear solves
  kSed,                ///< Merkel-layer strain energy density
  kReconstruction,     ///< contact reconstruction (fe.step: contact)
  kPress,              ///< press on the leader's model, its SED included (fe.step: contact)
  kLimiter,            ///< SED -> command mapping and safety limiter
  kPublish,            ///< LCM publishing of the field and the command
};
constexpr int kNumStages = 9;

/// Snake-case names, as in BRIDGE_STATUS fields and CSV columns ("solve"), in enum order
/// (the one name table, common/enum_names.h).
inline const config::EnumNames<Stage>& NamesOf(Stage) {
  static const config::EnumNames<Stage> names{
      {Stage::kConditioning, "conditioning"}, {Stage::kBoundaryCondition, "boundary_condition"},
      {Stage::kAssembly, "assembly"},         {Stage::kSolve, "solve"},
      {Stage::kSed, "sed"},                   {Stage::kReconstruction, "reconstruction"},
      {Stage::kPress, "press"},               {Stage::kLimiter, "limiter"},
      {Stage::kPublish, "publish"}};
  return names;
}
inline const char* ToString(Stage stage) { return config::NameCStrOf(stage); }

/// Wall time per stage [ms] of one step or scan (0 for stages that did not run).
struct StageTimes {
  std::array<double, kNumStages> ms{};

  double& operator[](Stage stage) { return ms[static_cast<size_t>(stage)]; }
  double operator[](Stage stage) const { return ms[static_cast<size_t>(stage)]; }
  /// Adds another report's times stage by stage (an FE step's into the scan's).
  void Add(const StageTimes& other) {
    for (int i = 0; i < kNumStages; ++i) ms[size_t(i)] += other.ms[size_t(i)];
  }
  double total_ms() const {
    double sum = 0;
    for (double t : ms) sum += t;
    return sum;
  }
};

/// "conditioning 0.012, solve 0.480, ..." [ms]: the stages with a time > 0, in order;
/// "none" when no stage has one.
inline std::string FormatStageTimes(const StageTimes& times) {
  std::string line;
  char buf[64];
  for (int i = 0; i < kNumStages; ++i) {
    if (!(times.ms[size_t(i)] > 0)) continue;
    std::snprintf(buf, sizeof buf, "%s%s %.3f", line.empty() ? "" : ", ", ToString(static_cast<Stage>(i)),
                  times.ms[size_t(i)]);
    line += buf;
  }
  return line.empty() ? "none" : line;
}

/// Adds the wall time from construction to destruction (or Stop()) to one stage.
class StageTimer {
 public:
  StageTimer(StageTimes& times, Stage stage) : times_(&times), stage_(stage), start_(Clock::now()) {}
  ~StageTimer() { Stop(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

  /// Adds the time so far and stops (later calls do nothing).
  void Stop() {
    if (!times_) return;
    (*times_)[stage_] += std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
    times_ = nullptr;
  }

 private:
  using Clock = std::chrono::steady_clock;
  StageTimes* times_;
  Stage stage_;
  Clock::time_point start_;
};

}  // namespace sedbridge
