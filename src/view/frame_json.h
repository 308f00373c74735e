#pragma once
// The view's wire format to the page: the mesh once (MeshJson), then one frame per update
// (FrameJson) with the latest of each message, laid out for drawing, and the timelines'
// recent window. Field names carry units; JSON null stands for "not in the messages".

#include <string>

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

std::string MeshJson(const SedMesh& mesh, const FrameStyle& style);

std::string FrameJson(const ViewState& state, ViewLayouts& layouts, const SedMesh& mesh, SedVertexMatch& match,
                      const PlaybackInfo& playback, const FrameStyle& style);

}  // namespace sedbridge::view
