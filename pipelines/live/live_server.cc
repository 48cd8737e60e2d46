#include "pipelines/live/live_server.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <thread>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/live/live_overlay.h"
#include "pipelines/live/request_guard.h"

// Last: <resolv.h>, which it includes, defines _res, a name inside Eigen.
#include <httplib.h>

namespace portcal {
namespace {

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::vector<uint8_t> Jpeg(const cv::Mat& bgr, int quality) {
  std::vector<uint8_t> bytes;
  cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return bytes;
}

void Reply(httplib::Response* response, const std::vector<uint8_t>& bytes, const char* type) {
  response->set_header("Cache-Control", "no-store");
  response->set_content(reinterpret_cast<const char*>(bytes.data()), bytes.size(), type);
}

nlohmann::json EstimateJson(const LiveEstimate& estimate) {
  nlohmann::json json;
  json["num_views"] = estimate.num_views;
  json["solved"] = estimate.solved;
  json["status"] = estimate.status;
  json["summary"] = estimate.Summary();
  json["rms_px"] = estimate.rms_px;
  nlohmann::json params = nlohmann::json::array();
  for (size_t k = 0; k < estimate.names.size(); ++k) {
    params.push_back({{"name", estimate.names[k]},
                      {"value", estimate.values[k]},
                      {"std_dev", estimate.std_devs[k]}});
  }
  json["params"] = params;
  json["uncertainty"] = {{"determined", estimate.uncertainty.determined},
                         {"mean_px", estimate.uncertainty.mean_px},
                         {"max_px", estimate.uncertainty.max_px}};
  if (estimate.next) {
    const Rigid3d& p = estimate.next->cam_from_target;
    json["next"] = {
        {"why", estimate.next->why},
        {"rotation_wxyz", {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()}},
        {"translation", {p.translation.x(), p.translation.y(), p.translation.z()}},
        {"distance_m", p.translation.norm()}};
  } else {
    json["next"] = nullptr;
    json["suggestion_error"] = estimate.suggestion_error;
  }
  if (estimate.camera2) json["camera2"] = EstimateJson(*estimate.camera2);
  if (estimate.rig) {
    const LiveRig& rig = *estimate.rig;
    const Eigen::Vector3d& t = rig.cam2_from_cam1.translation;
    json["rig"] = {{"solved", rig.solved},
                   {"status", rig.status},
                   {"translation", {t.x(), t.y(), t.z()}},
                   {"baseline_m", t.norm()},
                   {"translation_std_dev_m", rig.translation_std_dev.norm()},
                   {"rotation_std_dev_deg", rig.rotation_std_dev_deg.maxCoeff()},
                   {"rms_px", rig.rms_px}};
  }
  return json;
}

}  // namespace

void LivePageOptions::Check() const {
  const size_t colon = address.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == address.size() ||
      address.find_first_not_of("0123456789", colon + 1) != std::string::npos) {
    throw OptionError("--Live.address", address, "HOST:PORT, e.g. 127.0.0.1:8080 or 0.0.0.0:8080");
  }
  if (address.size() - colon - 1 > 5 || std::stoi(address.substr(colon + 1)) > 65535) {
    throw OptionError("--Live.address", address, "a port in [0, 65535]");
  }
  if (max_width < 64 || max_width > 8192) {
    throw OptionError("--Live.max_width", max_width, "in [64, 8192]");
  }
  if (!token.empty() && !IsValidLiveToken(token)) {
    throw OptionError("--Live.token", "(hidden)", "16-128 characters of A-Z, a-z, 0-9, _ and -");
  }
  if (jpeg_quality < 10 || jpeg_quality > 100) {
    throw OptionError("--Live.jpeg_quality", jpeg_quality, "[10, 100]");
  }
}

std::vector<uint8_t> EncodeOverlayJpeg(const LiveSnapshot& snapshot, const TargetShape& target,
                                       const LivePageOptions& options) {
  return Jpeg(DrawLiveOverlay(snapshot, target, options.max_width), options.jpeg_quality);
}

// The page with a fresh nonce on its one script and its one style, named
// by the Content-Security-Policy sent with it: those run, no other inline
// script does (what an injected name would need).
std::string PageWithNonce(const std::string& page, const std::string& nonce) {
  std::string html = page;
  for (const std::string tag : {"<script>", "<style>"}) {
    const size_t at = html.find(tag);
    PORTCAL_CHECK(at != std::string::npos);
    html.insert(at + tag.size() - 1, " nonce=\"" + nonce + "\"");
  }
  return html;
}

std::string NewNonce() {
  static std::mutex mutex;
  static std::random_device device;
  const std::lock_guard<std::mutex> lock(mutex);
  std::string nonce;
  for (int i = 0; i < 4; ++i) {
    char part[9];
    std::snprintf(part, sizeof(part), "%08x", static_cast<unsigned>(device()));
    nonce += part;
  }
  return nonce;
}

std::string ContentSecurityPolicy(const std::string& nonce) {
  const std::string inline_allowed = nonce.empty() ? "" : " 'nonce-" + nonce + "'";
  return "default-src 'none'; script-src 'self'" + inline_allowed + "; style-src 'self'" +
         inline_allowed +
         "; img-src 'self'; connect-src 'self'; base-uri 'none'; form-action 'none'; "
         "frame-ancestors 'none'";
}

// Viewers of the stream at once: each holds a server thread.
constexpr int kMaxStreamClients = 4;

struct LiveServer::Impl {
  LiveSession* session;
  std::atomic<int> stream_clients{0};
  LivePageOptions options;
  httplib::Server server;
  std::string host;
  int port = 0;
  std::thread listener;
  std::thread encoder;
  std::atomic<bool> stopping{false};
  std::atomic<double> last_viewer_s{-1e9};
  // The newest overlay, for every stream.
  mutable std::mutex mutex;
  std::condition_variable encoded;
  std::shared_ptr<const std::vector<uint8_t>> jpeg;
  int64_t jpeg_count = 0;
  double latency_sum_ms = 0;
  int64_t latency_count = 0;

  void EncodeLoop();
  void Routes();
  nlohmann::json State() const;
  bool StreamPart(int64_t* sent, httplib::DataSink& sink);
};

// Encodes each processed frame while someone watches (a stream asked for a
// frame within the last two seconds).
void LiveServer::Impl::EncodeLoop() {
  int64_t seen = 0;
  LiveSnapshot snapshot;
  while (!stopping) {
    if (!session->WaitForFrame(seen, 0.25, &snapshot)) {
      // The session has ended (WaitForFrame no longer waits) or no frame came.
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    seen = snapshot.frames_processed;
    if (WallSeconds() - last_viewer_s.load() > 2) continue;
    auto bytes = std::make_shared<const std::vector<uint8_t>>(
        EncodeOverlayJpeg(snapshot, session->target(), options));
    const double latency_ms = 1000 * (WallSeconds() - snapshot.arrival_wall_s);
    const std::lock_guard<std::mutex> lock(mutex);
    jpeg = bytes;
    ++jpeg_count;
    latency_sum_ms += latency_ms;
    ++latency_count;
    encoded.notify_all();
  }
}

bool LiveServer::Impl::StreamPart(int64_t* sent, httplib::DataSink& sink) {
  last_viewer_s = WallSeconds();
  std::shared_ptr<const std::vector<uint8_t>> part;
  {
    std::unique_lock<std::mutex> lock(mutex);
    encoded.wait_for(lock, std::chrono::seconds(1), [&] { return jpeg_count > *sent || stopping; });
    if (stopping) return false;
    if (jpeg_count == *sent) return sink.is_writable();  // no frame yet: keep the connection
    part = jpeg;
    *sent = jpeg_count;
  }
  const std::string header =
      "--frame\r\nContent-Type: image/jpeg\r\nContent-Length: " + std::to_string(part->size()) +
      "\r\n\r\n";
  return sink.write(header.data(), header.size()) &&
         sink.write(reinterpret_cast<const char*>(part->data()), part->size()) &&
         sink.write("\r\n", 2);
}

nlohmann::json LiveServer::Impl::State() const {
  const LiveSnapshot snapshot = session->Snapshot();
  nlohmann::json state;
  state["time_s"] = snapshot.time_s;
  state["frame"] = snapshot.frame_index;
  state["fps"] = snapshot.fps;
  state["width"] = snapshot.frame.cols;
  state["height"] = snapshot.frame.rows;
  state["target_seen"] = snapshot.target_seen;
  state["corners"] = snapshot.corners.size();
  state["held_s"] = snapshot.hold.held_s;
  state["still"] = snapshot.hold.still;
  state["message"] = snapshot.message;
  state["final"] = snapshot.final_status;
  state["output_path"] = options.output_path;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    state["latency_ms"] = latency_count > 0 ? latency_sum_ms / latency_count : 0.0;
  }
  nlohmann::json kept = nlohmann::json::array();
  for (const KeptView& view : snapshot.kept)
    kept.push_back({{"name", view.name}, {"points", view.view.pixels.size()}});
  state["kept"] = kept;
  state["coverage"] = CoverageFraction(snapshot);
  const LiveGoal& goal = snapshot.goal;
  state["goal"] = {{"target_px", goal.target_px},
                   {"determined", goal.determined},
                   {"mean_px", goal.mean_px},
                   {"max_px", goal.max_px},
                   {"met", goal.met},
                   {"progress", goal.progress},
                   {"limits", goal.limits},
                   {"summary", goal.Summary()}};
  state["estimate"] =
      snapshot.estimate ? EstimateJson(*snapshot.estimate) : nlohmann::json(nullptr);
  if (snapshot.to_suggestion) {
    state["to_suggestion"] = {{"outline_px", snapshot.to_suggestion->outline_px},
                              {"rotation_deg", snapshot.to_suggestion->rotation_deg},
                              {"translation_m", snapshot.to_suggestion->translation_m}};
  }
  return state;
}

void LiveServer::Impl::Routes() {
  server.Get("/", [this](const httplib::Request& request, httplib::Response& response) {
    if (!options.token.empty() && request.get_param_value("token") == options.token) {
      response.set_header("Set-Cookie", LiveTokenCookie(options.token));
    }
    const std::string nonce = NewNonce();
    response.set_header("Content-Security-Policy", ContentSecurityPolicy(nonce));
    response.set_content(PageWithNonce(LivePageHtml(), nonce), "text/html; charset=utf-8");
  });
  server.Get("/state.json", [this](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    response.set_content(State().dump(), "application/json");
  });
  server.Get("/stream.mjpg", [this](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    if (++stream_clients > kMaxStreamClients) {
      --stream_clients;
      response.status = 503;
      response.set_content(
          "too many viewers of the stream (" + std::to_string(kMaxStreamClients) + ")",
          "text/plain");
      return;
    }
    last_viewer_s = WallSeconds();
    auto sent = std::make_shared<int64_t>(0);
    response.set_chunked_content_provider(
        "multipart/x-mixed-replace; boundary=frame",
        [this, sent](size_t, httplib::DataSink& sink) { return StreamPart(sent.get(), sink); },
        [this](bool) { --stream_clients; });
  });
  server.Get("/coverage.jpg", [this](const httplib::Request&, httplib::Response& response) {
    Reply(&response, Jpeg(DrawCoverage(session->Snapshot(), options.max_width / 2), 85),
          "image/jpeg");
  });
  server.Get("/uncertainty.jpg", [this](const httplib::Request&, httplib::Response& response) {
    Reply(&response, Jpeg(DrawUncertainty(session->Snapshot(), options.max_width / 2), 85),
          "image/jpeg");
  });
  server.Get("/thumbnail", [this](const httplib::Request& request, httplib::Response& response) {
    const std::string name = request.get_param_value("name");
    for (const KeptView& view : session->Snapshot().kept) {
      if (view.name == name && !view.thumbnail.empty())
        return Reply(&response, Jpeg(view.thumbnail, 85), "image/jpeg");
    }
    response.status = 404;
  });
  using Action = std::function<void(const httplib::Request&)>;
  const std::map<std::string, Action> commands = {
      {"/capture", [this](const httplib::Request&) { session->Capture(); }},
      {"/undo", [this](const httplib::Request&) { session->Undo(); }},
      {"/calibrate", [this](const httplib::Request&) { session->CalibrateNow(); }},
      {"/finish", [this](const httplib::Request&) { session->Finish(); }},
      {"/remove",
       [this](const httplib::Request& request) {
         session->Remove(request.get_param_value("name"));
       }},
  };
  for (const auto& [path, action] : commands) {
    server.Post(path,
                [action = action](const httplib::Request& request, httplib::Response& response) {
                  action(request);
                  response.set_content("{\"ok\": true}", "application/json");
                });
  }
  // A POST with neither Content-Length nor Transfer-Encoding has no body
  // (RFC 9112, 6.3), but httplib 0.11 reads one until the client closes,
  // which a client waiting for the answer never does (`curl -X POST` hung).
  // The commands take no body: answer those before httplib reads.
  server.set_pre_routing_handler([this, commands](const httplib::Request& request,
                                                  httplib::Response& response) {
    const std::optional<std::string> refused = RefuseLiveRequest(
        {request.method, request.get_header_value("Host"), request.get_header_value("Origin"),
         request.get_header_value("Sec-Fetch-Site"), request.get_header_value("Cookie"),
         request.get_param_value("token")},
        port, options.token);
    if (refused) {
      LOG(WARNING) << "live: refused " << request.method << " " << request.path << ": " << *refused;
      response.status = 403;
      response.set_content("refused: " + *refused + "\n", "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    }
    const auto it = commands.find(request.path);
    if (request.method != "POST" || it == commands.end() || request.has_header("Content-Length") ||
        request.has_header("Transfer-Encoding")) {
      return httplib::Server::HandlerResponse::Unhandled;
    }
    it->second(request);
    response.set_content("{\"ok\": true}", "application/json");
    return httplib::Server::HandlerResponse::Handled;
  });
}

LiveServer::LiveServer(LiveSession* session, const LivePageOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  impl_->session = session;
  impl_->options = options;
  const size_t colon = options.address.rfind(':');
  impl_->host = options.address.substr(0, colon);
  const int port = std::stoi(options.address.substr(colon + 1));
  impl_->Routes();
  // Nothing but the page's own documents and images; no framing.
  impl_->server.set_post_routing_handler([](const httplib::Request&, httplib::Response& response) {
    if (!response.has_header("Content-Security-Policy")) {
      response.set_header("Content-Security-Policy", ContentSecurityPolicy(""));
    }
    response.set_header("X-Content-Type-Options", "nosniff");
    response.set_header("Referrer-Policy", "no-referrer");
  });
  // Idle or slow clients give their thread back within seconds; the pool
  // outnumbers the stream's cap, so the page stays answered.
  impl_->server.new_task_queue = [] { return new httplib::ThreadPool(4 * kMaxStreamClients + 8); };
  impl_->server.set_read_timeout(2);
  impl_->server.set_write_timeout(3);
  impl_->server.set_keep_alive_timeout(2);
  impl_->server.set_payload_max_length(1 << 16);
  // SO_REUSEADDR (a restart need not wait out TIME_WAIT) but not httplib's
  // default SO_REUSEPORT, with which a second session would share the port
  // silently, each answering half of the requests.
  impl_->server.set_socket_options([](socket_t socket) {
    int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  impl_->port = port == 0 ? impl_->server.bind_to_any_port(impl_->host) : port;
  if (impl_->port <= 0 || (port != 0 && !impl_->server.bind_to_port(impl_->host, port))) {
    throw InputError(
        "--Live.address " + options.address + ": cannot listen there (" +
        (port != 0 ? "is the port in use? try another, or 0 for a free one" : "no free port") +
        "; is the address one of this machine's?)");
  }
  impl_->listener = std::thread([impl = impl_.get()] { impl->server.listen_after_bind(); });
  // Serving before the constructor returns: a stop() before the listen
  // began would leave it running for good.
  for (int wait = 0; wait < 500 && !impl_->server.is_running(); ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  impl_->encoder = std::thread([impl = impl_.get()] { impl->EncodeLoop(); });
  LOG(INFO) << "live: the page is at " << url();
  if (impl_->host == "0.0.0.0" && options.token.empty()) {
    LOG(WARNING)
        << "live: serving on every network of this machine without a password: anyone who reaches "
        << "port " << impl_->port << " can end the session or remove views (set --Live.token)";
  }
}

LiveServer::~LiveServer() {
  impl_->stopping = true;
  impl_->encoded.notify_all();
  impl_->server.stop();
  if (impl_->listener.joinable()) impl_->listener.join();
  if (impl_->encoder.joinable()) impl_->encoder.join();
}

std::string LiveServer::url() const {
  const std::string host = impl_->host == "0.0.0.0" ? "127.0.0.1" : impl_->host;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/" +
         (impl_->options.token.empty() ? "" : "?token=" + impl_->options.token);
}

int LiveServer::port() const { return impl_->port; }

double LiveServer::mean_latency_ms() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->latency_count > 0 ? impl_->latency_sum_ms / impl_->latency_count : 0.0;
}

}  // namespace portcal
