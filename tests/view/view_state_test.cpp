// The view's model of the bus: messages by channel, size-safe decoding, timelines, the log
// player's seek and speed, and the JSON it sends.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "lcm/lcm_log_writer.h"
#include "view/frame_hub.h"
#include "view/frame_json.h"
#include "view/json_writer.h"
#include "view/log_player.h"
#include "view/sed_mesh.h"
#include "view/view_state.h"
#include "../lcm/lcm_test_messages.h"

namespace sedbridge::view {
namespace {

using lcm_io::test_messages::Encode;

lcmt_tactile_scan Scan(int64_t utime, float kPa) {
  lcmt_tactile_scan s{};
  s.utime = utime;
  s.sequence = utime / 10000;
  s.sensor_id = "uskin_4x4";
  s.num_taxels = 16;
  s.raw_counts.assign(16, 0);
  s.pressure_kPa.assign(16, kPa);
  s.valid.assign(16, 1);
  return s;
}

lcmt_merkel_sed Sed(int64_t utime, float peak) {
  lcmt_merkel_sed m{};
  m.utime = utime;
  m.model_id = "B";
  m.num_vertices = 2;
  m.num_positions = 2;
  m.x_mm = {0, 1};
  m.y_mm = {0, 0};
  m.z_mm = {-1, -1};
  m.sed_Pa = {peak / 2, peak};
  m.max_sed_Pa = peak;
  return m;
}

lcmt_display_command Command(int64_t utime, int64_t scan_utime) {
  lcmt_display_command c{};
  c.utime = utime;
  c.sequence = 1;
  c.source_scan_utime = scan_utime;
  c.display_id = "suction_4x4";
  c.unit = "kPa";
  c.num_actuators = 16;
  c.value.assign(16, 2.5f);
  return c;
}

template <typename Msg>
bool Feed(ViewState& s, const std::string& channel, const Msg& m, int64_t utime) {
  const std::vector<uint8_t> b = Encode(m);
  return s.OnEvent(channel, b.data(), b.size(), utime);
}

TEST(JsonWriter, NestsEscapesAndWritesNonFiniteAsNull) {
  JsonWriter w;
  w.BeginObject().Key("a").Numbers(std::vector<double>{1, NAN, INFINITY, 2.5}).Key("s").String("q\"\\\n");
  w.Key("o").BeginObject().Key("b").Bool(true).Key("n").Null().EndObject().Key("i").Ints({1, -2}).EndObject();
  EXPECT_EQ(w.str(), R"({"a":[1,null,null,2.5],"s":"q\"\\\u000a","o":{"b":true,"n":null},"i":[1,-2]})");
}

TEST(ViewState, TakesEachChannelsLatestAndRejectsBytesOfTheWrongSize) {
  ViewState s{lcm_io::LcmChannels{}};
  EXPECT_TRUE(Feed(s, "TACTILE_SCAN", Scan(1000000, 1.5f), 1000000));
  EXPECT_TRUE(Feed(s, "TACTILE_SCAN", Scan(1010000, 2.5f), 1010000));
  EXPECT_TRUE(Feed(s, "FINGERTIP_SED", Sed(1012000, 400), 1012000));
  EXPECT_TRUE(Feed(s, "DISPLAY_COMMAND", Command(1013000, 1010000), 1013000));
  EXPECT_TRUE(Feed(s, "SOMETHING_ELSE", Scan(1, 1), 1));  // not ours: ignored
  EXPECT_TRUE(Feed(s, "TACTILE_SCANNER", Scan(1, 1), 1));  // no '_' before the suffix: not ours
  ASSERT_EQ(s.fingers.size(), 1u);
  const FingerState& f = s.fingers[0];
  EXPECT_EQ(f.name, "");
  ASSERT_TRUE(f.have_scan && f.have_sed && f.have_command);
  EXPECT_FALSE(f.have_contact);
  EXPECT_FLOAT_EQ(f.scan.pressure_kPa[0], 2.5f);
  EXPECT_EQ(s.events, 4);
  ASSERT_EQ(f.latency_ms.value.size(), 1u);
  EXPECT_DOUBLE_EQ(f.latency_ms.value[0], 3.0);
  ASSERT_EQ(f.peak_sed_Pa.value.size(), 1u);
  EXPECT_NEAR(f.peak_sed_Pa.t_s[0], 0.012, 1e-12);

  // A scan whose taxel count its bytes cannot hold: rejected, the last good one stays.
  std::vector<uint8_t> bad = Encode(Scan(1020000, 9));
  bad.resize(bad.size() - 3);
  EXPECT_FALSE(s.OnEvent("TACTILE_SCAN", bad.data(), bad.size(), 1020000));
  EXPECT_EQ(s.rejected, 1);
  EXPECT_FLOAT_EQ(f.scan.pressure_kPa[0], 2.5f);

  const uint64_t before = s.version;
  s.Reset();
  EXPECT_FALSE(f.have_scan || f.have_sed || f.have_command);
  EXPECT_TRUE(f.latency_ms.t_s.empty());
  EXPECT_GT(s.version, before);
  EXPECT_EQ(s.fingers.size(), 1u);  // the panels stay
}

TEST(ViewState, FindsTheFingersOfAHandFromTheChannelNames) {
  ViewState s{lcm_io::LcmChannels{}};
  EXPECT_TRUE(Feed(s, "TACTILE_SCAN_THUMB", Scan(1000000, 1.0f), 1000000));
  EXPECT_TRUE(Feed(s, "TACTILE_SCAN_INDEX", Scan(1000000, 2.0f), 1000000));
  EXPECT_TRUE(Feed(s, "FINGERTIP_SED_INDEX", Sed(1002000, 300), 1002000));
  EXPECT_TRUE(Feed(s, "DISPLAY_COMMAND_THUMB", Command(1003000, 1000000), 1003000));
  EXPECT_TRUE(Feed(s, "TACTILE_SCAN_lower", Scan(1, 1), 1));  // not UPPER_SNAKE: not a finger
  ASSERT_EQ(s.fingers.size(), 2u);
  EXPECT_EQ(s.fingers[0].name, "THUMB");
  EXPECT_EQ(s.fingers[1].name, "INDEX");
  EXPECT_FLOAT_EQ(s.Finger("THUMB")->scan.pressure_kPa[0], 1.0f);
  EXPECT_FLOAT_EQ(s.Finger("INDEX")->scan.pressure_kPa[0], 2.0f);
  EXPECT_TRUE(s.Finger("INDEX")->have_sed);
  EXPECT_FALSE(s.Finger("THUMB")->have_sed);
  EXPECT_EQ(s.Finger("THUMB")->latency_ms.value.size(), 1u);

  // The index's target | delivered (DISPLAY_RENDERING), on its SED field's vertices.
  lcmt_display_rendering r{};
  r.command_sequence = 7;
  r.num_vertices = 2;
  r.target_sed_Pa = {150, 300};
  r.delivered_sed_Pa = {100, 200};
  r.max_target_sed_Pa = 300;
  r.max_delivered_sed_Pa = 200;
  EXPECT_TRUE(Feed(s, "DISPLAY_RENDERING_INDEX", r, 1004000));
  EXPECT_TRUE(s.Finger("INDEX")->have_rendering);
  Feed(s, "DISPLAY_COMMAND_INDEX", Command(1005000, 1000000), 1005000);
  std::map<std::string, SedVertexMatch> matches;
  ViewLayouts layouts("uskin_4x4", "suction_4x4");
  const std::string f = FrameJson(s, layouts, {}, matches, PlaybackInfo{}, FrameStyle{});
  EXPECT_NE(f.find(R"("delivered":{"utime":0,"command_sequence":7,"max_target_sed_Pa":300,"max_delivered_sed_Pa":200,)"
                   R"("x_mm":[0,1],"y_mm":[0,0],"target_sed_Pa":[150,300],"delivered_sed_Pa":[100,200],"limited":false})"),
            std::string::npos)
      << f;

  // A finger is one whose message decodes: bad bytes on a new name make none.
  std::vector<uint8_t> bad = Encode(Scan(1, 1));
  bad.resize(bad.size() - 3);
  EXPECT_FALSE(s.OnEvent("TACTILE_SCAN_RING", bad.data(), bad.size(), 1));
  EXPECT_EQ(s.Finger("RING"), nullptr);

  // No more than kMaxFingers, however many names a bus makes up.
  for (int k = 0; k < 40; ++k) Feed(s, "TACTILE_SCAN_F" + std::to_string(k), Scan(1, 1), 1);
  EXPECT_EQ(s.fingers.size(), ViewState::kMaxFingers);
  EXPECT_GT(s.ignored_fingers, 0);
}

TEST(SedVertexMatch, FindsTheFieldsVerticesOnTheMeshByPosition) {
  SedMesh mesh;
  mesh.merkel_xyz_mm = {5, 5, 5, 1, 0, -1, 0, 0, -1};
  SedVertexMatch match;
  const std::vector<int>& index = match.Match(mesh, {0.0f, 1.0004f, 9.0f}, {0, 0, 0}, {-1, -1, -1});
  EXPECT_EQ(index, (std::vector<int>{2, 1, -1}));
  EXPECT_EQ(match.matched(), 2u);
}

TEST(SedMesh, EachSkinVertexTakesTheMerkelVertexBeneathItAlongItsNormal) {
  SedMesh mesh;
  // A flat skin square at z = 0 facing +z (two triangles, counter-clockwise seen from +z).
  mesh.skin_xyz_mm = {0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 4, 0};
  mesh.skin_triangles = {0, 1, 2, 0, 2, 3};
  // Merkel vertices: 1 mm under corner 0, 0.2 mm off under corner 2 (the nearer of two),
  // one above corner 1 (outside the skin), one 5 mm under corner 3 (too deep).
  mesh.merkel_xyz_mm = {0, 0, -1, 4.2, 4, -1, 4, 4.6, -1, 4, 0, 1, 0, 4, -5};
  EXPECT_EQ(MapSkinToMerkel(mesh), (std::vector<int>{0, -1, 1, -1}));
}

TEST(SedMesh, ModelBsSkinOverThePadTakesItsMerkelLayer) {
  const SedMesh mesh = LoadSedMesh("B");
  ASSERT_TRUE(mesh.error.empty()) << mesh.error;
  ASSERT_EQ(mesh.skin_merkel.size(), mesh.skin_xyz_mm.size() / 3);
  std::size_t mapped = 0, pad = 0, pad_mapped = 0;
  for (std::size_t v = 0; v < mesh.skin_merkel.size(); ++v) {
    mapped += mesh.skin_merkel[v] >= 0;
    // The pad: the skin within 3 mm of the pad frame's origin (where the object presses).
    const double x = mesh.skin_xyz_mm[3 * v], y = mesh.skin_xyz_mm[3 * v + 1], z = mesh.skin_xyz_mm[3 * v + 2];
    if (std::hypot(x, y) < 3 && std::abs(z) < 0.5) ++pad, pad_mapped += mesh.skin_merkel[v] >= 0;
  }
  EXPECT_GT(pad, 0u);
  EXPECT_EQ(pad_mapped, pad);
  EXPECT_GT(mapped, 0u);
  std::printf("model B: %zu of %zu skin vertices over the Merkel layer's %zu\n", mapped, mesh.skin_merkel.size(),
              mesh.num_merkel_vertices());
}

TEST(FrameJson, CarriesTheLatestMessagesAndNullForWhatIsNotOnTheBus) {
  ViewState s{lcm_io::LcmChannels{}};
  Feed(s, "TACTILE_SCAN", Scan(1000000, 1.5f), 1000000);
  Feed(s, "FINGERTIP_SED", Sed(1002000, 300), 1002000);
  SedMesh mesh;
  mesh.model_id = "B";
  mesh.merkel_xyz_mm = {1, 0, -1, 0, 0, -1};
  mesh.merkel_triangles = {0, 1, 0};
  std::map<std::string, SedVertexMatch> matches;
  ViewLayouts layouts("uskin_4x4", "suction_4x4");
  const std::string f = FrameJson(s, layouts, {mesh}, matches, PlaybackInfo{}, FrameStyle{});
  EXPECT_NE(f.find(R"("fingers":[{"name":"","scan":{)"), std::string::npos) << f;
  EXPECT_NE(f.find(R"("pressure_kPa":[1.5,1.5,)"), std::string::npos) << f;
  EXPECT_NE(f.find(R"("on_mesh_Pa":[300,150])"), std::string::npos) << f;
  EXPECT_NE(f.find(R"("min_finite_Pa":150,"max_finite_Pa":300)"), std::string::npos) << f;
  EXPECT_NE(f.find(R"("contact":null)"), std::string::npos);
  EXPECT_NE(f.find(R"("display":null)"), std::string::npos);
  EXPECT_NE(f.find(R"("layout":{"id":"uskin_4x4")"), std::string::npos);
}

TEST(LogPlayer, PlaysOnTheLogsClockSeeksBackAndStopsAtTheEnd) {
  const std::string path = (std::filesystem::temp_directory_path() / "view_state_test.lcmlog").string();
  {
    lcm_io::LcmLogWriter w(path);
    for (int k = 0; k < 10; ++k) w.Write("TACTILE_SCAN", Scan(1000000 + k * 100000, float(k)));
    w.Write("FINGERTIP_SED", Sed(1500000, 800));
  }
  const auto any = [](const std::string&) { return true; };
  LogPlayer player({path}, any);
  EXPECT_NEAR(player.duration_s(), 0.9, 1e-9);
  EXPECT_DOUBLE_EQ(player.LargestSed_Pa([](const std::string& c) { return c == "FINGERTIP_SED"; }), 800);
  EXPECT_EQ(player.SedModels([](const std::string& c) { return c == "FINGERTIP_SED"; }), std::vector<std::string>{"B"});
  ViewState s{lcm_io::LcmChannels{}};
  player.Seek(0.45, &s);
  ASSERT_EQ(s.fingers.size(), 1u);
  const FingerState& f = s.fingers[0];
  EXPECT_FLOAT_EQ(f.scan.pressure_kPa[0], 4);
  player.SetSpeed(2);
  player.SetPlaying(true);
  player.Advance(0.1, &s);  // 0.2 s of log
  EXPECT_FLOAT_EQ(f.scan.pressure_kPa[0], 6);
  EXPECT_TRUE(f.have_sed);
  player.Seek(0.15, &s);  // backwards: replayed from the start
  EXPECT_FLOAT_EQ(f.scan.pressure_kPa[0], 1);
  EXPECT_FALSE(f.have_sed);
  player.Advance(10, &s);
  EXPECT_FLOAT_EQ(f.scan.pressure_kPa[0], 9);
  EXPECT_FALSE(player.playing());
  std::filesystem::remove(path);
}

TEST(FrameHub, AClientGetsOnlyNewerFramesAndCloseWakesIt) {
  FrameHub hub;
  uint64_t seen = 0;
  std::string frame;
  EXPECT_FALSE(hub.WaitNewer(&seen, &frame, std::chrono::milliseconds(1)));
  hub.Publish("a");
  hub.Publish("b");
  ASSERT_TRUE(hub.WaitNewer(&seen, &frame, std::chrono::milliseconds(1)));
  EXPECT_EQ(frame, "b");  // a slow client skips frames
  EXPECT_EQ(seen, 2u);
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    hub.Close();
  });
  EXPECT_FALSE(hub.WaitNewer(&seen, &frame, std::chrono::seconds(10)));
  closer.join();
}

}  // namespace
}  // namespace sedbridge::view
