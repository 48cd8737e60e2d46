// The live view as a web page served by portcal itself (cpp-httplib, from
// Debian): the camera is often on a vehicle's computer without a screen,
// its video reaching the person over a tether, so the view is a page any
// browser on that network opens, working offline (no CDN, no build step).
//
//   GET  /                  the page
//   GET  /stream.mjpg       the frames with the overlay (Motion JPEG)
//   GET  /state.json        the session: estimate, suggestion, kept views
//   GET  /coverage.jpg      the kept corners' heat-map
//   GET  /uncertainty.jpg   the expected projection uncertainty over the image
//   GET  /thumbnail?name=N  a kept view
//   POST /capture /undo /calibrate /finish, /remove?name=N
//
// Guarded as a local web UI (request_guard.h): its own Host and Origin
// only, an optional token, a Content-Security-Policy allowing the page's
// own script, style and images only, bounded threads and timeouts, and a
// cap on the stream's viewers.
#pragma once

#include <memory>
#include <string>

#include "pipelines/live/live_session.h"

namespace portcal {

struct LivePageOptions {
  // host:port; 127.0.0.1 for this machine only, 0.0.0.0 to be seen from the
  // vehicle's network; port 0 takes a free one.
  std::string address = "127.0.0.1:8080";
  bool headless = false;    // no page: state and suggestions on stderr only
  int max_width = 1280;     // frames on the page are scaled down to this width
  int jpeg_quality = 80;    // [10, 100]
  std::string output_path;  // shown on the page when the session ends
  // Required of every request when set (16-128 of [A-Za-z0-9_-]): the page
  // has no other password, which matters on a vehicle's shared network
  // (0.0.0.0). The printed address carries it; the page keeps it in a
  // cookie.
  std::string token;
  void Check() const;  // throws OptionError naming the --Live. option
};

// The JPEG encoder of the overlay, as the server runs it: drawing and
// encoding at most `max_width` wide. Exposed for the benchmark.
std::vector<uint8_t> EncodeOverlayJpeg(const LiveSnapshot& snapshot, const TargetShape& target,
                                       const LivePageOptions& options);

class LiveServer {
 public:
  // Listens at once. Throws InputError naming --Live.address when it
  // cannot (a port in use, an address not of this machine).
  LiveServer(LiveSession* session, const LivePageOptions& options);
  ~LiveServer();  // stops serving
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  std::string url() const;  // http://host:port/ (with ?token= when set)
  int port() const;
  // Mean time from a frame's arrival to its overlay being encoded, ms (the
  // page's latency, less the network).
  double mean_latency_ms() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The page (HTML, CSS and script in one, no outside resources).
const char* LivePageHtml();

}  // namespace portcal
