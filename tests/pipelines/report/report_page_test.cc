// Every calibrator's report.html in a real browser (Debian's headless
// chromium): the page loads every picture it names, and names the pictures
// each kind of calibration is meant to show. A check script, added to a
// copy of the page beside it, counts the images that loaded after the
// page's load event.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>

#include "colmap_ext/io/sparse_model.h"
#include "database/database.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/report/calibration_html.h"
#include "pipelines/stages/calibration_evaluator.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/cross_check.h"
#include "pipelines/stages/housing_calibrator.h"
#include "pipelines/stages/stereo_calibrator.h"
#include "pipelines/stages/synthesize.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr const char* kCamera =
    "camera: {model: RADIAL, width: 480, height: 360, params: [400.0, 243.0, 178.0, -0.06, "
    "0.01]}\n";
// A stereo rig's board has an odd number of columns: an even by even
// board looks the same turned half round, and the two cameras could number
// its corners the other way round.
constexpr const char* kRest =
    "poses: {distance: [0.3, 0.6], tilt_max_deg: 40, roll_max_deg: 30}\n"
    "render: {spp: 2, noise_sigma: 1.0}\n";

// Renders `name` (its housing / stereo lines given) and extracts its board
// (cols x 6 corners).
fs::path RenderAndExtract(const testing::TempDir& dir, const std::string& name,
                          const std::string& extra, bool per_folder = false, int cols = 8) {
  std::ofstream(dir / (name + ".yaml"))
      << "name: " << name << "\nseed: 7\nnum_images: 6\n"
      << kCamera << extra << "target: {type: chessboard, cols: " << cols
      << ", rows: 6, square_size: 0.025, margin: 0.015}\n"
      << kRest;
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / (name + ".yaml")).string();
  synthesize.output_path = (dir / name).string();
  RunSynthesize(synthesize, NoProgress());
  TargetExtractorOptions extract;
  extract.database_path = (dir / (name + ".db")).string();
  extract.image_path = (dir / name / "images").string();
  extract.reader.camera_model = "RADIAL";
  extract.reader.single_camera = !per_folder;
  extract.reader.single_camera_per_folder = per_folder;
  extract.chessboard.cols = cols;
  extract.chessboard.rows = 6;
  extract.square_size_m = 0.025;
  RunTargetExtractor(extract, NoProgress());
  return dir / (name + ".db");
}

struct PageLoad {
  int loaded = -1, total = -1;
  int overflows = -1, overlaps = -1;
  std::string layout;          // the first few offenders
  std::string verdict;         // "Verdict: OK", ... or "none"
  bool verdict_first = false;  // before the first section heading
};

// The page in `report_dir` as chromium loads it: how many of its images
// loaded. With `screenshot`, also a picture of the page.
PageLoad LoadInChromium(const testing::TempDir& dir, const fs::path& report_dir,
                        const fs::path& screenshot = {}) {
  std::string page = testing::ReadFileToString(report_dir / "report.html");
  const std::string check =
      "<script>window.addEventListener('load', () => { const images = [...document.images]; "
      "const ok = images.filter(i => i.complete && i.naturalWidth > 0).length; "
      "const d = document.createElement('div'); d.id = 'image-check'; "
      "d.textContent = 'loaded ' + ok + ' of ' + images.length; "
      // Layout: text that overflows its box or the page, and boxes of text
      // or pictures that overlap (neither inside the other).
      "const items = [...document.querySelectorAll('h1,h2,p,li,figcaption,pre,img')]; const bad = "
      "[]; "
      "const width = document.documentElement.clientWidth; "
      "for (const e of items) { const r = e.getBoundingClientRect(); "
      "  if ((e.tagName !== 'IMG' && e.scrollWidth > e.clientWidth + 1) || r.right > width + 1) "
      "    bad.push('overflow ' + e.tagName + ' ' + (e.textContent || e.src).slice(0, 60)); } "
      "let overlaps = 0; "
      "for (let i = 0; i < items.length; ++i) for (let j = i + 1; j < items.length; ++j) { "
      "  const a = items[i], b = items[j]; if (a.contains(b) || b.contains(a)) continue; "
      "  const p = a.getBoundingClientRect(), q = b.getBoundingClientRect(); "
      "  const w = Math.min(p.right, q.right) - Math.max(p.left, q.left), "
      "        h = Math.min(p.bottom, q.bottom) - Math.max(p.top, q.top); "
      "  if (w > 1 && h > 1) { ++overlaps; bad.push('overlap ' + a.tagName + '/' + b.tagName + ' ' "
      "+ "
      "    (a.textContent || a.src).slice(0, 40)); } } "
      "d.textContent += '; layout ' + (bad.length - overlaps) + ' overflows ' + overlaps + ' "
      "overlaps: ' + "
      "  bad.slice(0, 5).join(' | '); "
      "const v = document.getElementById('verdict'); "
      "d.textContent += '; verdict ' + (v ? v.querySelector('p').textContent : 'none') + ' first ' "
      "+ "
      "  (v !== null && v.compareDocumentPosition(document.querySelector('h2')) === 4); "
      "document.body.appendChild(d); });</script>";
  page.insert(page.rfind("</body>"), check);
  std::ofstream(report_dir / "report_check.html") << page;
  const std::string chromium =
      "timeout 90 chromium --headless --no-sandbox --disable-gpu --no-first-run "
      "--disable-background-networking "
      "--disable-component-update --disable-sync --user-data-dir=" +
      (dir / "profile").string() + " --window-size=1200,2400 --virtual-time-budget=5000 ";
  const testing::CommandResult dom =
      testing::RunCommand(chromium + "--dump-dom 'file://" +
                          (report_dir / "report_check.html").string() + "' 2>/dev/null");
  if (!screenshot.empty()) {
    fs::create_directories(screenshot.parent_path());
    testing::RunCommand(chromium + "--screenshot=" + screenshot.string() + " 'file://" +
                        (report_dir / "report.html").string() + "' 2>/dev/null");
  }
  std::smatch match;
  PageLoad load;
  if (std::regex_search(dom.output, match, std::regex("loaded ([0-9]+) of ([0-9]+)"))) {
    load.loaded = std::stoi(match[1]);
    load.total = std::stoi(match[2]);
  }
  if (std::regex_search(dom.output, match,
                        std::regex("layout ([0-9]+) overflows ([0-9]+) overlaps: ([^;]*); verdict "
                                   "([^<]*?) first (true|false)"))) {
    load.overflows = std::stoi(match[1]);
    load.overlaps = std::stoi(match[2]);
    load.layout = match[3];
    load.verdict = match[4];
    load.verdict_first = match[5] == "true";
  }
  return load;
}

void ExpectAllLoaded(const testing::TempDir& dir, const fs::path& report_dir, int num_pictures,
                     const fs::path& screenshot = {}) {
  const PageLoad load = LoadInChromium(dir, report_dir, screenshot);
  EXPECT_EQ(load.total, num_pictures) << report_dir;
  EXPECT_EQ(load.loaded, load.total) << report_dir;
  EXPECT_EQ(load.overflows, 0) << report_dir << ": " << load.layout;
  EXPECT_EQ(load.overlaps, 0) << report_dir << ": " << load.layout;
  EXPECT_EQ(load.verdict.rfind("Verdict: ", 0), 0u) << report_dir << ": no verdict";
  EXPECT_TRUE(load.verdict_first) << report_dir << ": the verdict does not open the page";
}

// A self-calibration's model from target views at their poses: the board's
// corners as the points, the views as the images.
SparseModel ModelOfViews(const std::vector<CalibrationView>& views,
                         const HousingCalibrationResult& result) {
  SparseModel model;
  model.cameras[1] = result.camera;
  model.housings[1] = result.housing;
  std::map<std::pair<double, double>, point3D_t> ids;
  for (size_t v = 0; v < views.size(); ++v) {
    Image image;
    image.image_id = static_cast<image_t>(v + 1);
    image.name = views[v].image_name;
    image.camera_id = 1;
    image.cam_from_world = result.views[v].cam_from_target;
    for (size_t i = 0; i < views[v].pixels.size(); ++i) {
      const Eigen::Vector3d& x = views[v].points_in_target[i];
      const auto [it, added] =
          ids.emplace(std::make_pair(x.x(), x.y()), static_cast<point3D_t>(ids.size() + 1));
      model.points3D[it->second].xyz = x;
      model.points3D[it->second].track.push_back({image.image_id, static_cast<point2D_t>(i)});
      image.points2D.push_back({views[v].pixels[i], it->second});
    }
    model.images[image.image_id] = image;
  }
  return model;
}

TEST(ReportPage, EveryCalibratorsPageLoadsEveryPicture) {
  if (testing::RunCommand("command -v chromium").exit_code != 0) {
    GTEST_SKIP() << "chromium is not installed (bash workflows/test.sh installs it)";
  }
  const testing::TempDir dir;
  const fs::path air = RenderAndExtract(dir, "air", "housing: null\n");
  const fs::path dome = RenderAndExtract(dir, "dome",
                                         "housing: {model: DOMEPORT, params: [0.003, -0.002, "
                                         "0.005, 0.05, 0.006, 1.0, 1.473, 1.334]}\n");
  const fs::path stereo = RenderAndExtract(
      dir, "stereo",
      "housing: null\nstereo:\n  cam2_from_cam1: {rotation_axis_angle_deg: [0.0, 1.0, 0.0, -4.0], "
      "translation: [-0.08, 0.0, 0.004]}\n",
      /*per_folder=*/true, /*cols=*/9);

  CameraCalibratorOptions camera;
  camera.database_path = air.string();
  camera.output_path = (dir / "out/air").string();
  camera.image_path = (dir / "air/images").string();
  RunCameraCalibrator(camera, NoProgress());
  // coverage, per-view RMS, residuals, their histogram, the worst views, the
  // thumbnails, uncertainty near and at infinity, distortion, correlation
  ExpectAllLoaded(dir, dir / "out/air", 10, fs::current_path() / "artifacts/report_camera.png");

  HousingCalibratorOptions housing;
  housing.database_path = dome.string();
  housing.in_air_database_path = air.string();
  housing.output_path = (dir / "out/dome").string();
  housing.housing =
      Housing::FromName("DOMEPORT", {0, 0, 0, 0.05, 0.006, 1.0, 1.473, 1.334}, "test");
  const HousingCalibrationResult housing_result = RunHousingCalibrator(housing, NoProgress());
  ExpectAllLoaded(
      dir, dir / "out/dome", 10,
      fs::current_path() / "artifacts/report_housing.png");  // no thumbnails, + the housing

  CalibrationEvaluatorOptions evaluator;
  evaluator.database_path = dome.string();
  evaluator.input_calibration = (dir / "out/dome/calibration.yaml").string();
  evaluator.output_path = (dir / "out/evaluation").string();
  RunCalibrationEvaluator(evaluator, NoProgress());
  ExpectAllLoaded(dir, dir / "out/evaluation", 5);  // coverage, RMS, residuals, histogram, pattern

  CrossCheckOptions cross_check;
  cross_check.database_path = air.string();
  cross_check.input_calibration = (dir / "out/air/calibration.yaml").string();
  cross_check.output_path = (dir / "out/cross_check").string();
  RunCrossCheck(cross_check, NoProgress());
  ExpectAllLoaded(dir, dir / "out/cross_check", 10);  // the difference map + portcal's nine

  StereoCalibratorOptions rig;
  rig.database_path = stereo.string();
  rig.output_path = (dir / "out/stereo").string();
  RunStereoCalibrator(rig, NoProgress());
  // The rig, and four per camera.
  ExpectAllLoaded(dir, dir / "out/stereo", 9, fs::current_path() / "artifacts/report_stereo.png");

  Database database(dome, Database::OpenMode::kReadOnly);
  const std::vector<CalibrationView> views = ReadTargetViews(&database).by_camera.begin()->second;
  CalibrationReport report = ReportOf(housing_result, "chessboard");
  report.pose_frame = "world";
  const SparseModel self_model = ModelOfViews(views, housing_result);
  report.verdict = JudgeCalibration(report, self_model, 1);  // as the self-calibrating stages judge
  WriteHtml(SelfCalibrationHtml(report, self_model, "Auto-calibration"), dir / "out/self");
  ExpectAllLoaded(dir, dir / "out/self", 5);  // scene, coverage, RMS, residuals, housing
}

}  // namespace
}  // namespace portcal
