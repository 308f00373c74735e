#include "view/view_server.h"

#include <httplib.h>

#include <chrono>
#include <stdexcept>

namespace sedbridge::view {
namespace {

constexpr char kJson[] = "application/json";

// A client that reads nothing for this long is given up (its stream thread is freed).
constexpr auto kWriteTimeout = std::chrono::seconds(5);
// An idle stream sends a comment this often, so a page that left is noticed.
constexpr auto kKeepAlive = std::chrono::milliseconds(500);
// Threads that event streams may not take, so a page can still load with many streams open.
constexpr int kThreadsKeptFree = 8;

bool WriteEvent(httplib::DataSink& sink, const std::string& frame) {
  const std::string event = "event: frame\ndata: " + frame + "\n\n";
  return sink.write(event.data(), event.size());
}

}  // namespace

ViewServer::ViewServer(ViewServerOptions options, FrameHub* hub, MeshSource mesh, Control control)
    : options_(std::move(options)), hub_(hub), mesh_(std::move(mesh)), control_(std::move(control)),
      server_(std::make_unique<httplib::Server>()) {
  const int threads = options_.threads;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(std::size_t(threads)); };
  server_->set_write_timeout(std::chrono::duration_cast<std::chrono::seconds>(kWriteTimeout).count(), 0);
  server_->set_read_timeout(5, 0);
  server_->set_payload_max_length(4096);  // the only body is a short control command
  Routes();
}

ViewServer::~ViewServer() { Stop(); }

void ViewServer::Routes() {
  httplib::Server& s = *server_;
  if (!options_.web_dir.empty()) s.set_mount_point("/", options_.web_dir);
  s.Get("/api/mesh", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(mesh_(), kJson);
  });
  s.Get("/api/frame", [this](const httplib::Request&, httplib::Response& res) {
    uint64_t number = 0;
    const std::string frame = hub_->Latest(&number);
    if (number == 0) {
      res.status = 503;
      res.set_content("{\"error\":\"no frame yet\"}", kJson);
      return;
    }
    res.set_content(frame, kJson);
  });
  s.Get("/api/events", [this](const httplib::Request&, httplib::Response& res) {
    // Each stream holds a thread: keep some for the pages' other requests.
    if (hub_->clients.load() >= options_.threads - kThreadsKeptFree) {
      res.status = 503;
      res.set_content("too many pages open\n", "text/plain");
      return;
    }
    res.set_header("Cache-Control", "no-cache");
    ++hub_->clients;
    ++hub_->clients_total;
    struct Stream {
      uint64_t seen = 0;  ///< number of the last frame sent
      bool started = false;
    };
    auto stream = std::make_shared<Stream>();
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, stream](std::size_t, httplib::DataSink& sink) {
          std::string frame;
          if (!stream->started) {
            stream->started = true;
            static const std::string hello = "retry: 1000\n\n";
            if (!sink.write(hello.data(), hello.size())) return false;
            frame = hub_->Latest(&stream->seen);
            if (stream->seen > 0) {
              if (!WriteEvent(sink, frame)) return false;
              ++hub_->frames_sent;
            }
          }
          while (!hub_->closed()) {
            if (hub_->WaitNewer(&stream->seen, &frame, kKeepAlive)) {
              if (!WriteEvent(sink, frame)) return false;  // the page left
              ++hub_->frames_sent;
            } else if (!hub_->closed()) {
              static const std::string ping = ": keep-alive\n\n";
              if (!sink.write(ping.data(), ping.size())) return false;
            }
          }
          sink.done();
          return true;
        },
        [this](bool) { --hub_->clients; });
  });
  s.Post("/api/control", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string why = control_ ? control_(req.body) : "this view has no playback to control";
    if (!why.empty()) {
      res.status = 400;
      res.set_content(why + "\n", "text/plain");
      return;
    }
    res.set_content("ok\n", "text/plain");
  });
}

void ViewServer::Start() {
  if (options_.port == 0) {
    port_ = server_->bind_to_any_port(options_.bind);
    if (port_ < 0) throw std::runtime_error("cannot bind " + options_.bind + " on any port");
  } else {
    if (!server_->bind_to_port(options_.bind, options_.port))
      throw std::runtime_error("cannot bind " + options_.bind + ":" + std::to_string(options_.port) +
                               " (in use? try --port 0)");
    port_ = options_.port;
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
}

void ViewServer::Stop() {
  hub_->Close();
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace sedbridge::view
