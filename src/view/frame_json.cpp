#include "view/frame_json.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "view/json_writer.h"

namespace sedbridge::view {
namespace {

void WriteLayout(JsonWriter& w, const PadLayout& l) {
  w.Key("layout").BeginObject();
  w.Key("id").String(l.id);
  w.Key("x_mm").Numbers(l.x_mm).Key("y_mm").Numbers(l.y_mm);
  w.Key("cell_w_mm").Number(l.cell_w_mm).Key("cell_h_mm").Number(l.cell_h_mm);
  w.Key("max").Number(l.max).Key("unit").String(l.unit);
  w.EndObject();
}

// The window [end - window, end] of a series, every k-th point so at most `points` remain
// (the last point always).
void WriteSeries(JsonWriter& w, const char* key, const Series& s, const FrameStyle& style) {
  std::vector<double> t, v;
  if (!s.t_s.empty()) {
    const double start = s.t_s.back() - style.timeline_window_s;
    const std::size_t first = std::size_t(std::lower_bound(s.t_s.begin(), s.t_s.end(), start) - s.t_s.begin());
    const std::size_t n = s.t_s.size() - first;
    const std::size_t step = std::max<std::size_t>(1, (n + std::size_t(style.timeline_points) - 1) / std::size_t(style.timeline_points));
    for (std::size_t i = first; i < s.t_s.size(); i += step) t.push_back(s.t_s[i]), v.push_back(s.value[i]);
    if (t.back() != s.t_s.back()) t.push_back(s.t_s.back()), v.push_back(s.value.back());
  }
  w.Key(key).BeginObject().Key("t_s").Numbers(t, 7).Key("v").Numbers(v).EndObject();
}

void WriteScan(JsonWriter& w, const FingerState& s, ViewLayouts& layouts) {
  w.Key("scan");
  if (!s.have_scan) {
    w.Null();
    return;
  }
  const lcmt_tactile_scan& m = s.scan;
  w.BeginObject();
  w.Key("utime").Int(m.utime).Key("sequence").Int(m.sequence).Key("sensor_id").String(m.sensor_id);
  w.Key("pressure_kPa").Numbers(m.pressure_kPa);
  std::vector<int> valid(m.valid.begin(), m.valid.end());
  w.Key("valid").Ints(valid);
  // A three-axis sensor's shear per taxel; null for a normal-only one (or a log from before).
  const bool shear = m.num_shear > 0 && m.shear_x_kPa.size() == m.pressure_kPa.size();
  w.Key("shear_x_kPa");
  if (shear) w.Numbers(m.shear_x_kPa);
  else w.Null();
  w.Key("shear_y_kPa");
  if (shear) w.Numbers(m.shear_y_kPa);
  else w.Null();
  const PadLayout& l = layouts.Sensor(m.sensor_id);
  if (l.x_mm.size() == m.pressure_kPa.size()) WriteLayout(w, l);
  else w.Key("layout").Null();
  w.EndObject();
}

void WriteContact(JsonWriter& w, const FingerState& s) {
  w.Key("contact");
  if (!s.have_contact) {
    w.Null();
    return;
  }
  const lcmt_contact_estimate& c = s.contact;
  w.BeginObject();
  w.Key("utime").Int(c.utime).Key("source_scan_utime").Int(c.source_scan_utime).Key("shape").Int(c.shape);
  w.Key("x_mm").Number(c.x_mm).Key("y_mm").Number(c.y_mm).Key("radius_mm").Number(c.radius_mm);
  w.Key("yaw_deg").Number(c.yaw_deg).Key("length_mm").Number(c.length_mm);
  w.Key("normal_force_N").Number(c.normal_force_N).Key("shear_x_N").Number(c.shear_x_N).Key("shear_y_N").Number(c.shear_y_N);
  w.Key("x2_mm").Number(c.x2_mm).Key("y2_mm").Number(c.y2_mm).Key("radius2_mm").Number(c.radius2_mm);
  w.Key("normal_force2_N").Number(c.normal_force2_N);
  w.Key("residual_rms_sigma").Number(c.residual_rms_sigma).Key("fallback").Bool(c.fallback != 0);
  w.Key("indentation_mm").Number(c.indentation_mm);
  std::vector<int> used(c.taxel_used.begin(), c.taxel_used.end());
  w.Key("taxel_used").Ints(used);
  w.EndObject();
}

void WriteSed(JsonWriter& w, const FingerState& s, const std::vector<SedMesh>& meshes, SedVertexMatch& match) {
  w.Key("sed");
  if (!s.have_sed) {
    w.Null();
    return;
  }
  const lcmt_merkel_sed& m = s.sed;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float e : m.sed_Pa)
    if (std::isfinite(e)) lo = std::min(lo, double(e)), hi = std::max(hi, double(e));
  w.BeginObject();
  w.Key("utime").Int(m.utime).Key("source_scan_utime").Int(m.source_scan_utime).Key("model_id").String(m.model_id);
  w.Key("num_vertices").Int(m.num_vertices).Key("max_sed_Pa").Number(m.max_sed_Pa);
  w.Key("min_finite_Pa").Number(lo).Key("max_finite_Pa").Number(hi);
  const bool positions = m.num_positions == m.num_vertices;
  int mesh_index = -1;
  const SedMesh* mesh = MeshFor(meshes, m.model_id, &mesh_index);
  std::vector<double> on_mesh(mesh ? mesh->num_merkel_vertices() : 0, std::numeric_limits<double>::quiet_NaN());
  std::size_t matched = 0;
  if (positions && !on_mesh.empty()) {
    const std::vector<int>& index = match.Match(*mesh, m.x_mm, m.y_mm, m.z_mm);
    for (std::size_t k = 0; k < index.size(); ++k)
      if (index[k] >= 0) on_mesh[std::size_t(index[k])] = m.sed_Pa[k];
    matched = match.matched();
  }
  w.Key("matched_vertices").Int(int64_t(matched));
  w.Key("mesh").Int(matched > 0 ? mesh_index : -1);
  if (matched > 0) {
    w.Key("on_mesh_Pa").Numbers(on_mesh, 4);
  } else if (positions) {
    // No mesh (or none matched): the field's own points.
    w.Key("points").BeginObject().Key("x_mm").Numbers(m.x_mm).Key("y_mm").Numbers(m.y_mm).Key("z_mm").Numbers(m.z_mm);
    w.Key("sed_Pa").Numbers(m.sed_Pa, 4).EndObject();
  }
  w.EndObject();
}

// The target and delivered SED (DISPLAY_RENDERING) on the pad's side of the Merkel layer: its
// vertices within 1.5 mm of the layer's top (the layer wraps the tip; the display touches the
// pad), placed by the SED field's positions (the same vertices, in the same order).
void WriteDelivered(JsonWriter& w, const FingerState& s) {
  w.Key("delivered");
  const lcmt_display_rendering& r = s.rendering;
  const lcmt_merkel_sed& m = s.sed;
  const std::size_t n = r.target_sed_Pa.size();
  if (!s.have_rendering || !s.have_sed || m.num_positions != m.num_vertices || m.x_mm.size() != n) {
    w.Null();
    return;
  }
  float top = -std::numeric_limits<float>::infinity();
  for (float z : m.z_mm) top = std::max(top, z);
  std::vector<double> x, y, target, delivered;
  for (std::size_t v = 0; v < n; ++v) {
    if (!(m.z_mm[v] >= top - 1.5f)) continue;
    x.push_back(m.x_mm[v]), y.push_back(m.y_mm[v]);
    target.push_back(r.target_sed_Pa[v]), delivered.push_back(r.delivered_sed_Pa[v]);
  }
  w.BeginObject();
  w.Key("utime").Int(r.utime).Key("command_sequence").Int(r.command_sequence);
  w.Key("max_target_sed_Pa").Number(r.max_target_sed_Pa).Key("max_delivered_sed_Pa").Number(r.max_delivered_sed_Pa);
  w.Key("x_mm").Numbers(x, 5).Key("y_mm").Numbers(y, 5);
  w.Key("target_sed_Pa").Numbers(target, 4).Key("delivered_sed_Pa").Numbers(delivered, 4);
  w.Key("limited").Bool(r.limited != 0);
  w.EndObject();
}

void WriteDisplay(JsonWriter& w, const FingerState& s, ViewLayouts& layouts) {
  w.Key("display");
  if (!s.have_command) {
    w.Null();
    return;
  }
  const lcmt_display_command& c = s.command;
  w.BeginObject();
  w.Key("utime").Int(c.utime).Key("sequence").Int(c.sequence).Key("source_scan_utime").Int(c.source_scan_utime);
  w.Key("display_id").String(c.display_id).Key("unit").String(c.unit);
  w.Key("commanded").Numbers(c.value);
  w.Key("clamped").Bool(c.clamped).Key("stale").Bool(c.stale).Key("fault").Bool(c.fault).Key("shutdown").Bool(c.shutdown);
  const PadLayout& l = layouts.Display(c.display_id);
  if (l.x_mm.size() == c.value.size()) WriteLayout(w, l);
  else w.Key("layout").Null();
  // The target at the sites: the SED the mapping read at each (SA1_RATE_ESTIMATE carries it);
  // the whole fields, target and delivered, under "delivered" (DISPLAY_RENDERING).
  const bool target = s.have_sa1 && s.sa1.display_id == c.display_id && s.sa1.sed_Pa.size() == c.value.size();
  w.Key("target_sed_Pa");
  if (target) w.Numbers(s.sa1.sed_Pa);
  else w.Null();
  w.Key("sa1_rate_Hz");
  if (target) w.Numbers(s.sa1.rate_Hz);
  else w.Null();
  WriteDelivered(w, s);
  w.EndObject();
}

void WriteStatus(JsonWriter& w, const FingerState& s) {
  w.Key("status");
  if (!s.have_status) {
    w.Null();
    return;
  }
  const lcmt_bridge_status& b = s.status;
  w.BeginObject();
  w.Key("utime").Int(b.utime).Key("scan_rate_Hz").Number(b.scan_rate_Hz).Key("command_rate_Hz").Number(b.command_rate_Hz);
  w.Key("latency_p50_ms").Number(b.latency_p50_ms).Key("latency_p99_ms").Number(b.latency_p99_ms);
  w.Key("latency_max_ms").Number(b.latency_max_ms).Key("scans_dropped").Int(b.scans_dropped);
  w.Key("fault_state").Int(b.fault_state).Key("fault_message").String(b.fault_message);
  w.EndObject();
}

void WriteTriangles(JsonWriter& w, const char* key, const std::vector<double>& xyz, const std::vector<int>& tris) {
  w.Key(key).BeginObject().Key("xyz_mm").Numbers(xyz, 6).Key("triangles").Ints(tris).EndObject();
}

}  // namespace

const SedMesh* MeshFor(const std::vector<SedMesh>& meshes, const std::string& model_id, int* index) {
  *index = -1;
  for (std::size_t k = 0; k < meshes.size(); ++k)
    if (meshes[k].model_id == model_id) *index = int(k);
  if (*index < 0 && !meshes.empty()) *index = 0;
  return *index < 0 ? nullptr : &meshes[std::size_t(*index)];
}

std::string MeshJson(const std::vector<SedMesh>& meshes, const FrameStyle& style) {
  JsonWriter w;
  w.BeginObject();
  w.Key("sed_scale_Pa").Number(style.sed_scale_Pa);
  w.Key("meshes").BeginArray();
  for (const SedMesh& mesh : meshes) {
    w.BeginObject();
    w.Key("model_id").String(mesh.model_id).Key("error").String(mesh.error);
    WriteTriangles(w, "merkel", mesh.merkel_xyz_mm, mesh.merkel_triangles);
    WriteTriangles(w, "skin", mesh.skin_xyz_mm, mesh.skin_triangles);
    w.Key("skin_merkel").Ints(mesh.skin_merkel);
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
  return w.str();
}

std::string FrameJson(const ViewState& state, ViewLayouts& layouts, const std::vector<SedMesh>& meshes,
                      std::map<std::string, SedVertexMatch>& matches, const PlaybackInfo& playback,
                      const FrameStyle& style) {
  JsonWriter w;
  w.BeginObject();
  w.Key("version").Int(int64_t(state.version));
  w.Key("playback").BeginObject();
  w.Key("live").Bool(playback.live).Key("source").String(playback.source);
  w.Key("position_s").Number(playback.position_s).Key("duration_s").Number(playback.duration_s);
  w.Key("playing").Bool(playback.playing).Key("speed").Number(playback.speed);
  w.EndObject();
  w.Key("sed_scale_Pa").Number(style.sed_scale_Pa);
  w.Key("events").Int(state.events).Key("rejected").Int(state.rejected);
  w.Key("fingers").BeginArray();
  for (const FingerState& f : state.fingers) {
    w.BeginObject();
    w.Key("name").String(f.name);
    WriteScan(w, f, layouts);
    WriteContact(w, f);
    WriteSed(w, f, meshes, matches[f.name]);
    WriteDisplay(w, f, layouts);
    WriteStatus(w, f);
    w.Key("timeline").BeginObject();
    WriteSeries(w, "force_N", f.force_N, style);
    WriteSeries(w, "peak_sed_Pa", f.peak_sed_Pa, style);
    WriteSeries(w, "latency_ms", f.latency_ms, style);
    w.EndObject();
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
  return w.str();
}

}  // namespace sedbridge::view
