#pragma once
// The view's HTTP side (cpp-httplib, Debian's libcpp-httplib-dev: one header, no runtime to
// ship, and Server-Sent Events are a chunked response it streams as it is written):
//   GET  /                 the page and its files (web_dir: the build's or the install's copy)
//   GET  /api/mesh         the fingertip mesh, once per page
//   GET  /api/frame        the latest frame (JSON)
//   GET  /api/events       the frames as they come (text/event-stream)
//   POST /api/control      playback of a log: "play", "pause", "seek S", "speed X"
// Nothing here reaches the bridge or the display: the view only reads LCM.

#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "view/frame_hub.h"

namespace httplib {
class Server;
}

namespace sedbridge::view {

struct ViewServerOptions {
  std::string bind = "127.0.0.1";
  int port = 8053;  ///< 0: any free port (port() tells which)
  std::string web_dir;
  int threads = 64;  ///< each open page holds one for its event stream (at most threads - 8 streams)
};

class ViewServer {
 public:
  using MeshSource = std::function<std::string()>;
  /// Returns "" when done, else why the command was refused.
  using Control = std::function<std::string(const std::string& command)>;

  ViewServer(ViewServerOptions options, FrameHub* hub, MeshSource mesh, Control control);
  ~ViewServer();

  /// Binds and serves on a thread of its own; throws std::runtime_error when it cannot bind.
  void Start();
  /// Closes every stream and stops serving.
  void Stop();
  int port() const { return port_; }

 private:
  void Routes();
  ViewServerOptions options_;
  FrameHub* hub_;
  MeshSource mesh_;
  Control control_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace sedbridge::view
