// End to end with a lying taxel: the example log with one taxel edited (as
// tools/edit_taxel_log.py does) through the whole bridge. Stuck high from the first scan:
// no display command before the contact; dead under the contact: the peak SED within the
// fidelity targets of the healthy log's (ratio 0.8-1.25).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bridge/replay.h"
#include "bridge_test_util.h"
#include "sensors/candump_log.h"

namespace sedbridge::bridge {
namespace {

// uskin_4x4: taxel k's frame has id 0x710 + k, z (normal) big-endian in bytes 5-6, 0.0005 N
// per count.
constexpr int kIdBase = 0x710;
constexpr int kQuietScans = 25;  // the log's first scans: nothing touches

enum class Fault { kStuck, kDead };

// The example log with `taxel` repeating its first quiet scans' readings (noise, no load),
// plus 2.5 N (5000 counts) when stuck.
std::string EditedLog(int taxel, Fault fault) {
  std::ifstream in(testing::ExampleLogPath());
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  char id[8];
  std::snprintf(id, sizeof id, "%X#", kIdBase + taxel);
  std::vector<std::string> quiet;
  for (const std::string& l : lines)
    if (l.find(std::string(" ") + id) != std::string::npos && int(quiet.size()) < kQuietScans) quiet.push_back(l.substr(l.find('#') + 1));
  const auto path = std::filesystem::temp_directory_path() /
                    ("sedbridge_faulty_taxel_" + std::to_string(int(fault)) + "_" + std::to_string(::getpid()) + ".log");
  std::ofstream out(path);
  size_t k = 0;
  for (std::string l : lines) {
    const size_t hash = l.find(std::string(" ") + id);
    if (hash != std::string::npos) {
      std::string data = quiet[k++ % quiet.size()];
      if (fault == Fault::kStuck) {
        const int z = std::min(0xFFFF, std::stoi(data.substr(10, 4), nullptr, 16) + 5000);
        char hex[5];
        std::snprintf(hex, sizeof hex, "%04X", z);
        data.replace(10, 4, hex);
      }
      l = l.substr(0, l.find('#') + 1) + data;
    }
    out << l << '\n';
  }
  return path.string();
}

ReplayResult Replay(const std::string& log, FeStepKind step = FeStepKind::kContact) {
  BridgeConfig config = testing::TestConfig();
  config.fe_step = step;  // the default bridge's (the test config's default is the pressure map)
  config.compliance_cache_dir = "";
  sensors::CandumpLogSource source(log);
  return testing::ReplayWithConfigProfiles(config, source, ReplayOptions{});
}

double PeakSed_Pa(const ReplayResult& r) {
  double peak = 0;
  for (const ReplayRow& row : r.rows) peak = std::max(peak, row.max_sed_Pa);
  return peak;
}

TEST(FaultyTaxelReplay, StuckTaxelGivesNoDisplayCommandBeforeContact) {
  for (int taxel : {5, 0}) {
    const std::string log = EditedLog(taxel, Fault::kStuck);
    const ReplayResult r = Replay(log);
    std::filesystem::remove(log);
    ASSERT_EQ(r.rows.size(), 300u);
    for (size_t i = 0; i < 75; ++i)  // contact starts about 0.8 s into the log
      EXPECT_EQ(r.rows[i].max_command, 0.0) << "taxel " << taxel << " scan " << i;
    EXPECT_NE(r.taxel_health.find("1 masked now (" + std::to_string(taxel) + " stuck high)"), std::string::npos)
        << r.taxel_health;
    EXPECT_LT(r.scans_at_ceiling, 20) << "taxel " << taxel;  // 299 of 300 before
  }
}

TEST(FaultyTaxelReplay, DeadTaxelUnderTheContactKeepsThePeakSedWithinTheFidelityTargets) {
  const std::string log = EditedLog(5, Fault::kDead);
  for (FeStepKind step : {FeStepKind::kContact, FeStepKind::kScene}) {
    const double healthy = PeakSed_Pa(Replay(testing::ExampleLogPath(), step));
    const ReplayResult r = Replay(log, step);
    const double ratio = PeakSed_Pa(r) / healthy;
    std::printf("fe.step %s, dead taxel 5: peak SED %.1f Pa, healthy %.1f Pa (ratio %.3f); %s\n",
                step == FeStepKind::kContact ? "contact" : "scene", PeakSed_Pa(r), healthy, ratio, r.taxel_health.c_str());
    EXPECT_NE(r.taxel_health.find("(5 dead)"), std::string::npos) << r.taxel_health;
    if (step != FeStepKind::kContact) continue;  // the pressure map: printed (a masked taxel's fill is capped by its ring)
    EXPECT_GE(ratio, 0.8);
    EXPECT_LE(ratio, 1.25);
  }
  std::filesystem::remove(log);
}

}  // namespace
}  // namespace sedbridge::bridge
