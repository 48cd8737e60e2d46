// The live page in a real browser (Debian's headless chromium): it loads
// from a running live_calibrator, its stream moves on, its capture and undo
// buttons work; a screenshot is kept as an artefact. Also the page's HTTP
// endpoints, a port already in use, and Ctrl-C on the real process.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/stages/live_calibrator.h"
#include "tests/pipelines/stages/live_test_setup.h"

// Last: <resolv.h>, which it includes, defines _res, a name inside Eigen.
#include <httplib.h>

namespace fs = std::filesystem;

namespace portcal {
namespace {

// Three pauses: 34 frames.
const std::string kTrajectoryYaml = testing::LiveTrajectoryYaml(4, 3, false);

LiveCalibratorOptions Options(const testing::TempDir& dir) {
  LiveCalibratorOptions options = testing::LiveOptions(dir, (dir / "set/images").string());
  // 34 s: the browser (slow to start on a busy machine) finds the session
  // running; the test finishes it as soon as it is done.
  options.live.source.folder_fps = 1;
  options.live.estimator.guidance.num_candidates = 60;
  options.page.headless = false;
  options.page.address = "127.0.0.1:0";
  options.calibrate_at_end = false;
  return options;
}

// The first line of the answer to a raw request (as `curl -X POST` sends
// one: no Content-Length, no body), or "" after 3 s without one.
std::string RawRequestStatus(int port, const std::string& request) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval timeout{3, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  std::string reply;
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
      send(fd, request.data(), request.size(), 0) == static_cast<ssize_t>(request.size())) {
    char buffer[256];
    const ssize_t n = recv(fd, buffer, sizeof(buffer), 0);
    if (n > 0) reply.assign(buffer, static_cast<size_t>(n));
  }
  close(fd);
  return reply.substr(0, reply.find("\r\n"));
}

// Headless chromium as the machine's probe runs it, with a fresh profile.
std::string Chromium(const testing::TempDir& dir, const std::string& what, const std::string& url) {
  return "timeout 90 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
         "--disable-background-networking --disable-component-update --disable-sync "
         "--user-data-dir=" +
         (dir / ("profile_" + std::to_string(std::hash<std::string>()(what)))).string() +
         " --window-size=1400,1000 --virtual-time-budget=15000 " + what + " '" + url +
         "' 2>/dev/null";
}

TEST(LivePage, ABrowserSeesTheStreamAndItsButtonsWork) {
  if (testing::RunCommand("command -v chromium").exit_code != 0) {
    GTEST_SKIP() << "chromium is not installed (bash workflows/test.sh installs it)";
  }
  const testing::TempDir dir;
  testing::RenderSet(dir, kTrajectoryYaml);
  std::promise<std::string> url_promise;
  LiveSession* session = nullptr;
  auto run = std::async(std::launch::async, [&] {
    return RunLiveCalibrator(Options(dir), NoProgress(),
                             [&](LiveSession& s, const std::string& url) {
                               session = &s;
                               url_promise.set_value(url);
                             });
  });
  const std::string url = url_promise.get_future().get();
  ASSERT_FALSE(url.empty());
  const std::smatch port = [&] {
    std::smatch match;
    std::regex_search(url, match, std::regex(":([0-9]+)/"));
    return match;
  }();
  httplib::Client client("127.0.0.1", std::stoi(port[1]));

  // The page presses its own buttons (?selftest=1) and writes what happened.
  const testing::CommandResult dom =
      testing::RunCommand(Chromium(dir, "--dump-dom", url + "?selftest=1"));
  EXPECT_NE(dom.output.find("selftest: passed"), std::string::npos) << dom.output.substr(0, 4000);
  EXPECT_NE(dom.output.find("capture: "), std::string::npos);
  EXPECT_NE(dom.output.find("layout: no text overflows its box"), std::string::npos)
      << dom.output.substr(0, 4000);

  // A screenshot, kept beside the test binary for a person to look at.
  const fs::path artefact = fs::current_path() / "artifacts/live_page.png";
  fs::create_directories(artefact.parent_path());
  testing::RunCommand(Chromium(dir, "--screenshot=" + artefact.string(), url));
  EXPECT_GT(fs::exists(artefact) ? fs::file_size(artefact) : 0, 20000u) << artefact;

  // The endpoints themselves.
  const auto state = client.Get("/state.json");
  ASSERT_TRUE(state && state->status == 200);
  const nlohmann::json json = nlohmann::json::parse(state->body);
  EXPECT_EQ(json["width"], 640);
  std::string stream;
  client.Get("/stream.mjpg", [&](const char* data, size_t length) {
    stream.append(data, length);
    return stream.size() < 20000;  // enough for a part
  });
  EXPECT_NE(stream.find("--frame\r\nContent-Type: image/jpeg"), std::string::npos);
  EXPECT_NE(stream.find("\xff\xd8"), std::string::npos) << "no JPEG in the stream";
  for (const char* image : {"/coverage.jpg", "/uncertainty.jpg"}) {
    const auto reply = client.Get(image);
    ASSERT_TRUE(reply && reply->status == 200) << image;
    EXPECT_EQ(reply->get_header_value("Content-Type"), "image/jpeg");
  }

  // Another session on the same port: a clear error naming the option.
  try {
    LivePageOptions taken;
    taken.address = "127.0.0.1:" + std::string(port[1]);
    LiveServer second(session, taken);
    ADD_FAILURE() << "a second server on a port in use";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--Live.address"), std::string::npos) << e.what();
  }

  // The guard. A command from another origin, a foreign Host (DNS
  // rebinding), a page another site serves: refused, the session goes on.
  const int live_port = std::stoi(port[1]);
  EXPECT_EQ(RawRequestStatus(live_port,
                             "POST /finish HTTP/1.1\r\nHost: 127.0.0.1:" + std::string(port[1]) +
                                 "\r\nOrigin: http://evil.example\r\n\r\n"),
            "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(RawRequestStatus(live_port, "GET /state.json HTTP/1.1\r\nHost: evil.example:" +
                                            std::string(port[1]) + "\r\n\r\n"),
            "HTTP/1.1 403 Forbidden");
  const fs::path evil = dir / "evil.html";
  std::ofstream(evil)
      << "<!DOCTYPE html><html><body><p id=r>sent</p><script>fetch('http://127.0.0.1:" << port[1]
      << "/finish', {method: 'POST', mode: 'no-cors'}).catch(() => {});"
         "fetch('http://127.0.0.1:"
      << port[1]
      << "/remove?name=live_0001.png', {method: 'POST', "
         "mode: 'no-cors'}).catch(() => {});</script></body></html>";
  testing::RunCommand(Chromium(dir, "--dump-dom", "file://" + evil.string()));
  const auto after = client.Get("/state.json");
  ASSERT_TRUE(after && after->status == 200);
  EXPECT_EQ(nlohmann::json::parse(after->body)["final"], "") << "another page ended the session";
  // The page: a Content-Security-Policy naming the page's own nonce, and
  // no name ever parsed as HTML.
  const auto page = client.Get("/");
  ASSERT_TRUE(page && page->status == 200);
  EXPECT_NE(page->get_header_value("Content-Security-Policy").find("script-src 'self' 'nonce-"),
            std::string::npos);
  EXPECT_EQ(page->body.find("innerHTML"), std::string::npos);

  // As `curl -X POST URL/finish` sends it: answered at once, and done.
  EXPECT_EQ(
      RawRequestStatus(std::stoi(port[1]), "POST /finish HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"),
      "HTTP/1.1 200 OK");
  const LiveCalibratorSummary summary = run.get();
  EXPECT_EQ(summary.session.end_reason, "finish requested");
  Database database(dir / "live.db", Database::OpenMode::kReadOnly);
  EXPECT_EQ(database.NumImages(), summary.session.kept);
}

// A hostile file name among the kept views of a continued session: the
// page shows it as text; no element is made of it (names reach the page
// through textContent only).
TEST(LivePage, AHostileImageNameShowsAsText) {
  if (testing::RunCommand("command -v chromium").exit_code != 0) {
    GTEST_SKIP() << "chromium is not installed (bash workflows/test.sh installs it)";
  }
  const testing::TempDir dir;
  testing::RenderSet(dir, kTrajectoryYaml);
  std::vector<fs::path> frames;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir / "set/images"))
    frames.push_back(entry.path());
  std::sort(frames.begin(), frames.end());
  const int held = testing::TrajectoryPauses(dir / "set/trajectory.yaml").at(0).first;
  const std::string hostile = "<img src=x onerror=document.title=7>.png";
  fs::create_directories(dir / "kept");
  fs::copy_file(frames.at(static_cast<size_t>(held)), dir / "kept" / hostile);
  testing::ExtractBoard(dir / "kept", dir / "live.db", false);
  std::promise<std::string> url_promise;
  auto run = std::async(std::launch::async, [&] {
    return RunLiveCalibrator(Options(dir), NoProgress(), [&](LiveSession&, const std::string& url) {
      url_promise.set_value(url);
    });
  });
  const std::string url = url_promise.get_future().get();
  ASSERT_FALSE(url.empty());
  const testing::CommandResult dom = testing::RunCommand(Chromium(dir, "--dump-dom", url));
  EXPECT_NE(dom.output.find("&lt;img src=x onerror=document.title=7&gt;.png"), std::string::npos)
      << "the kept name is not on the page as text: " << dom.output.substr(0, 4000);
  EXPECT_EQ(dom.output.find("<img src=\"x\""), std::string::npos) << "a name became an element";
  EXPECT_EQ(dom.output.find("<title>7</title>"), std::string::npos) << "a name's script ran";
  std::smatch port;
  ASSERT_TRUE(std::regex_search(url, port, std::regex(":([0-9]+)/")));
  httplib::Client client("127.0.0.1", std::stoi(port[1]));
  ASSERT_TRUE(client.Post("/finish"));
  run.get();
}

// A rig: the page shows both cameras side by side, each camera's estimate
// and the relative pose once three pairs are kept, and at the end the final
// calibration's outcome.
TEST(LivePage, ARigShowsBothCamerasAndTheRelativePose) {
  const testing::TempDir dir;
  testing::RenderSet(dir, testing::LiveStereoTrajectoryYaml(11, 4, false));
  LiveCalibratorOptions options = Options(dir);
  options.live.source.source = (dir / "set/images/cam1").string();
  options.live.source2 = (dir / "set/images/cam2").string();
  // 75 frames at 2.5 a second: the rig is solved at frame 46 (18 s), and
  // the source must outlast the checks after it (a browser's screenshot
  // takes seconds on a loaded machine) so that /finish finds the session;
  // at 5 a second it ended first beside a 16 GB mapping.
  options.live.source.folder_fps = 2.5;
  options.calibrate_at_end = true;
  std::promise<std::string> url_promise;
  auto run = std::async(std::launch::async, [&] {
    return RunLiveCalibrator(options, NoProgress(), [&](LiveSession&, const std::string& url) {
      url_promise.set_value(url);
    });
  });
  const std::string url = url_promise.get_future().get();
  std::smatch port;
  ASSERT_TRUE(std::regex_search(url, port, std::regex(":([0-9]+)/")));
  httplib::Client client("127.0.0.1", std::stoi(port[1]));
  nlohmann::json estimate;
  for (int wait = 0; wait < 800; ++wait) {
    const auto state = client.Get("/state.json");
    ASSERT_TRUE(state && state->status == 200);
    estimate = nlohmann::json::parse(state->body)["estimate"];
    if (estimate.is_object() && estimate.contains("rig") && estimate["rig"]["solved"] == true)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(estimate.is_object() && estimate.contains("rig")) << estimate.dump();
  EXPECT_EQ(estimate["rig"]["solved"], true) << estimate.dump();
  EXPECT_NEAR(estimate["rig"]["baseline_m"].get<double>(), 0.1, 0.002);
  EXPECT_EQ(estimate["camera2"]["solved"], true);
  EXPECT_FALSE(estimate["next"].is_null()) << estimate.dump();
  std::string stream;
  client.Get("/stream.mjpg", [&](const char* data, size_t length) {
    stream.append(data, length);
    return stream.size() < 60000;
  });
  const size_t start = stream.find("\xff\xd8");
  ASSERT_NE(start, std::string::npos);
  const cv::Mat frame =
      cv::imdecode(std::vector<uint8_t>(stream.begin() + start, stream.end()), cv::IMREAD_COLOR);
  ASSERT_FALSE(frame.empty());
  EXPECT_NEAR(frame.cols, 2 * frame.rows * 640 / 480, 2) << "not two 640 x 480 frames side by side";
  if (testing::RunCommand("command -v chromium").exit_code == 0) {
    const fs::path artefact = fs::current_path() / "artifacts/live_page_stereo.png";
    fs::create_directories(artefact.parent_path());
    testing::RunCommand(Chromium(dir, "--screenshot=" + artefact.string(), url));
    EXPECT_GT(fs::exists(artefact) ? fs::file_size(artefact) : 0, 20000u) << artefact;
  }
  // Finish: the page is told of the final calibration before it goes.
  ASSERT_TRUE(client.Post("/finish"));
  std::string final_status;
  for (int wait = 0; wait < 200 && final_status.find("reports in") == std::string::npos; ++wait) {
    const auto state = client.Get("/state.json");
    if (!state) break;
    final_status = nlohmann::json::parse(state->body)["final"].get<std::string>();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_NE(final_status.find("reports in " + (dir / "out").string()), std::string::npos)
      << final_status;
  EXPECT_NE(final_status.find("baseline"), std::string::npos) << final_status;
  const LiveCalibratorSummary summary = run.get();
  EXPECT_TRUE(summary.calibrated && summary.stereo);
  Database database(dir / "live.db", Database::OpenMode::kReadOnly);
  EXPECT_EQ(database.NumImages(), 2 * summary.session.kept);
}

TEST(LivePage, CtrlCOnTheProcessKeepsEveryViewItReported) {
  const testing::TempDir dir;
  testing::RenderSet(dir, kTrajectoryYaml);
  const std::string log = (dir / "log.txt").string();
  const std::string command =
      testing::PortcalBinary() + " live_calibrator --source " + (dir / "set/images").string() +
      " --Live.fps 4 --Live.headless 1 --database_path " + (dir / "live.db").string() +
      " --image_path " + (dir / "kept").string() + " --output_path " + (dir / "out").string() +
      " --Target.cols 9 --Target.rows 6 --Target.square_size 0.03 "
      "--ImageReader.camera_model OPENCV --Live.distance_range 0.35,0.8";
  // In the background (its own output away from RunCommand's pipe, which
  // would wait for it); SIGINT once the second view is kept.
  testing::RunCommand("(" + command + " > " + log + " 2>&1; echo exit=$? >> " + log +
                      ") > /dev/null 2>&1 &");
  int kept = 0;
  for (int wait = 0; wait < 300 && kept < 2; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const std::string text = testing::ReadFileToString(log);
    kept = 0;
    for (size_t at = text.find("live: kept "); at != std::string::npos;
         at = text.find("live: kept ", at + 1))
      ++kept;
  }
  ASSERT_GE(kept, 2) << testing::ReadFileToString(log);
  testing::RunCommand("pkill -INT -f 'live_calibrator --source " + (dir / "set/images").string() +
                      "'");
  std::string text;
  for (int wait = 0; wait < 200 && text.find("exit=") == std::string::npos; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    text = testing::ReadFileToString(log);
  }
  EXPECT_NE(text.find("exit=130"), std::string::npos) << text;
  size_t reported = 0;
  for (size_t at = text.find("live: kept "); at != std::string::npos;
       at = text.find("live: kept ", at + 1))
    ++reported;
  Database database(dir / "live.db", Database::OpenMode::kReadOnly);
  EXPECT_EQ(static_cast<size_t>(database.NumImages()), reported);
  for (const DatabaseImage& image : database.ReadAllImages())
    EXPECT_TRUE(fs::exists(dir / "kept" / image.name));
}

}  // namespace
}  // namespace portcal
