#pragma once
// The view's wire format to the page: the meshes once (MeshJson), then one frame per update
// (FrameJson) with, per finger, the latest of each message, laid out for drawing, and the
// timelines' recent window. Field names carry units; JSON null stands for "not in the
// messages".

#include <map>
#include <string>
#include <vector>

#include "view/sed_mesh.h"
#include "view/view_layouts.h"
#include "view/view_state.h"

namespace sedbridge::view {

/// Where the view's source is: a log being played, or a live bus.
struct PlaybackInfo {
  bool live = false;
  std::string source;   ///< log path or LCM URL
  double position_s = 0, duration_s = 0;
  bool playing = false;
  double speed = 1;
};

struct FrameStyle {
  double sed_scale_Pa = 1000;  ///< the fixed top of the SED colour scale [Pa]
  double timeline_window_s = 20;
  int timeline_points = 400;   ///< at most this many points per series in a frame
};

/// {"sed_scale_Pa", "meshes": [{"model_id", "error", "merkel", "skin", "skin_merkel"}, ...]}
std::string MeshJson(const std::vector<SedMesh>& meshes, const FrameStyle& style);

/// The mesh a finger's SED field is drawn on: the one of its model_id, else the first (a
/// --model given by hand), else nullptr. Its index in `meshes` in *index.
const SedMesh* MeshFor(const std::vector<SedMesh>& meshes, const std::string& model_id, int* index);

/// {"version", "playback", "fingers": [{"name", "scan", "contact", "sed", "display", "status",
/// "timeline"}, ...]}; `matches` keeps each finger's SED vertex match between frames.
std::string FrameJson(const ViewState& state, ViewLayouts& layouts, const std::vector<SedMesh>& meshes,
                      std::map<std::string, SedVertexMatch>& matches, const PlaybackInfo& playback,
                      const FrameStyle& style);

}  // namespace sedbridge::view
