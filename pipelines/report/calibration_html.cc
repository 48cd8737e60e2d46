#include "pipelines/report/calibration_html.h"

#include <cmath>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/report/calibration_pictures.h"
#include "pipelines/report/geometry_pictures.h"
#include "pipelines/report/lens_pictures.h"
#include "pipelines/report/picture.h"
#include "pipelines/report/view_pictures.h"

namespace portcal {

namespace {

std::vector<Eigen::Vector2d> AllPixels(const std::vector<CalibrationView>& views) {
  std::vector<Eigen::Vector2d> pixels;
  for (const CalibrationView& view : views)
    pixels.insert(pixels.end(), view.pixels.begin(), view.pixels.end());
  return pixels;
}

// Coverage, per-view RMS, residual vectors and the residuals' histogram of
// views at their poses, file names prefixed by `prefix`. The histogram's
// Gaussian has the fit's residual sigma, or where there is none (held-out
// views) the residuals' own RMS per axis.
std::vector<ReportPicture> ViewPictures(const ViewsAtPoses& at_poses, double residual_sigma_px,
                                        const std::string& prefix, const std::string& what) {
  const Camera& camera = at_poses.camera.camera;
  const int num_views = static_cast<int>(at_poses.calibrated.size());
  const std::vector<PointResidual> residuals = ResidualsAtPoses(at_poses);
  std::vector<Eigen::Vector2d> kept;
  double sum_squares = 0;
  for (const PointResidual& r : residuals) {
    if (r.dropped) continue;
    kept.push_back(r.residual);
    sum_squares += r.residual.squaredNorm();
  }
  const double sigma = residual_sigma_px > 0
                           ? residual_sigma_px
                           : std::sqrt(sum_squares / std::max<size_t>(1, 2 * kept.size()));
  return {
      {prefix + "coverage.png",
       "Where the corners lie over the image" + what +
           ": the model is trusted where they are, extrapolated where cells are dark or empty.",
       CoveragePicture(camera, AllPixels(at_poses.views), "corners")},
      {prefix + "per_view_rms.png",
       "Each view's RMS reprojection error; a view well above the dashed line is suspect (blur, a "
       "misdetected "
       "corner, a moved board).",
       PerViewRmsPicture(at_poses.calibrated, residual_sigma_px, "Per-view RMS" + what)},
      {prefix + "residuals.png",
       "Residual vectors (observed - predicted), magnified, one colour per view. Noise points "
       "every way; arrows "
       "that line up or swirl over a region mean the model does not fit there.",
       ResidualVectorsPicture(camera, residuals, num_views, "Residuals" + what)},
      {prefix + "residual_histogram.png",
       "The residuals' x and y components against the Gaussian of the fitted noise (red). Noise "
       "follows the "
       "curve; a heavier tail, or a peak off zero, is outliers or a model error.",
       ResidualHistogramPicture(kept, sigma, "Residuals" + what)},
  };
}

std::vector<int> HeldParams(const CalibrationReport& report) {
  std::vector<int> held;
  for (size_t i = 0; i < report.parameters_std_dev.size(); ++i) {
    if (report.parameters_std_dev[i] == 0) held.push_back(static_cast<int>(i));
  }
  return held;
}

// A housing calibration on given intrinsics: the housing's uncertainty;
// else (a camera, or a joint solve) the intrinsics' (seen through the
// housing, if any).
bool OfHousing(const CalibrationReport& report) {
  return report.housing.has_value() && HeldParams(report).size() == report.camera.params.size();
}

}  // namespace

ProjectionUncertaintyGrid ProjectionUncertaintyOf(const CalibrationReport& report,
                                                  const std::vector<CalibrationView>& views) {
  const ViewsAtPoses at_poses{HousedCamera{report.camera, report.housing}, views, report.views,
                              report.board_warp};
  return ProjectionUncertaintyOfViews(at_poses, OfHousing(report), HeldParams(report),
                                      report.residual_sigma_px);
}

HtmlVerdict HtmlVerdictOf(const CalibrationVerdict& verdict) {
  HtmlVerdict html{VerdictStatusName(verdict.status), {}};
  for (const VerdictLine& line : verdict.lines)
    html.lines.push_back({VerdictStatusName(line.status), line.rule, line.text});
  return html;
}

HtmlReport CalibrationHtml(const CalibrationReport& report,
                           const std::vector<CalibrationView>& views, const std::string& title,
                           const std::filesystem::path& image_root) {
  ViewsAtPoses at_poses{HousedCamera{report.camera, report.housing}, views, report.views,
                        report.board_warp};
  HtmlReport html{title, report.warnings, {}, {}};
  if (report.verdict) html.verdict = HtmlVerdictOf(*report.verdict);
  ReportSection section{"The views", "", ViewPictures(at_poses, report.residual_sigma_px, "", "")};
  section.pictures.push_back(
      {"worst_views.png",
       std::string("The views of highest RMS") +
           (image_root.empty() ? " (give --image_path to see their images)" : "") +
           ", their residuals magnified: a single wild arrow is a misdetected corner; arrows all "
           "one way, a moved "
           "or blurred board.",
       WorstViewsPicture(at_poses, image_root)});
  const cv::Mat thumbnails = ThumbnailsPicture(at_poses, image_root);
  if (!thumbnails.empty()) {
    section.pictures.push_back(
        {"views.png",
         "Every view with its detected corners: check that each board was found "
         "whole and where it is.",
         thumbnails});
  }
  const bool housing = report.housing.has_value();
  const ProjectionUncertaintyGrid uncertainty = report.projection_uncertainty
                                                    ? *report.projection_uncertainty
                                                    : ProjectionUncertaintyOf(report, views);
  section.pictures.push_back(
      {"uncertainty.png",
       std::string("How far (px, one sigma, worst direction) a point at the views' median distance "
                   "may project "
                   "from where this calibration puts it, from the ") +
           (OfHousing(report) ? "housing's" : "intrinsics'") +
           " uncertainty given these views: mrcal's measure (mean-frames), the point fixed to the "
           "targets, not "
           "to the camera (the line: the mean). It grows where the views give little information.",
       UncertaintyPicture(uncertainty, static_cast<int>(report.camera.width),
                          static_cast<int>(report.camera.height))});
  section.pictures.push_back({"uncertainty_infinity.png",
                              "The same at infinity: how far a distant point's projection may be "
                              "off (it grows where the views were all "
                              "near, and with what the lens's far field was not seen).",
                              UncertaintyPicture(uncertainty, static_cast<int>(report.camera.width),
                                                 static_cast<int>(report.camera.height), true)});
  html.sections.push_back(section);
  std::vector<ReportPicture> lens{{"distortion.png",
                                   "How far each pixel's ray lands from where a pinhole of the "
                                   "same focal lengths and principal point puts it "
                                   "(iso-lines at 1, 10 and 100 px). The white outline is where "
                                   "corners were seen: outside it the model is "
                                   "extrapolated.",
                                   DistortionPicture(report.camera, AllPixels(views))}};
  const bool lens_estimated = report.parameters_covariance.size() > 0 &&
                              report.parameters_covariance.diagonal().maxCoeff() > 0;
  const cv::Mat correlation =
      lens_estimated ? CorrelationPicture(report.parameters_covariance,
                                          SplitTokens(report.camera.ParamsInfo(), ", "),
                                          "Correlation of the intrinsics")
      : report.housing && report.housing_covariance.size() > 0
          ? CorrelationPicture(report.housing_covariance,
                               SplitTokens(report.housing->ParamsInfo(), ", "),
                               "Correlation of the housing's parameters")
          : cv::Mat();
  if (!correlation.empty()) {
    lens.push_back({"correlation.png",
                    "The estimated parameters' correlations (held ones left out): near +-1, the "
                    "views could not tell "
                    "the two apart, and their values trade against each other (e.g. fx with a "
                    "dome's axial offset).",
                    correlation});
  }
  html.sections.push_back({"The lens", "", lens});
  if (housing) {
    html.sections.push_back({"The housing",
                             "",
                             {{"housing.png", "The housing to scale, from above and from the side.",
                               HousingPicture(*report.housing)}}});
  }
  html.sections.push_back({"Report (calibration.txt)", CalibrationReportText(report), {}});
  return html;
}

HtmlReport StereoCalibrationHtml(const StereoCalibrationResult& result,
                                 const std::vector<CalibrationView>& views1,
                                 const std::vector<CalibrationView>& views2,
                                 const std::string& report_text) {
  HtmlReport html{"Stereo calibration", {}, {}, {}};
  std::vector<Rigid3d> cam1_from_target;
  for (const CalibratedView& view : result.views1) cam1_from_target.push_back(view.cam_from_target);
  html.sections.push_back(
      {"The rig",
       "",
       {{"rig.png",
         "The rig from above: the two cameras, their fields of view, and the target's "
         "positions. The baseline and the convergence should look like the rig.",
         RigFromAbovePicture(result.camera1, result.cam2_from_cam1, cam1_from_target)}}});
  const std::vector<const std::vector<CalibrationView>*> views = {&views1, &views2};
  const std::vector<const Camera*> cameras = {&result.camera1, &result.camera2};
  const std::vector<const std::vector<CalibratedView>*> calibrated = {&result.views1,
                                                                      &result.views2};
  for (int k = 0; k < 2; ++k) {
    const std::string name = "camera " + std::to_string(k + 1);
    const ViewsAtPoses at_poses{HousedCamera{*cameras[k], std::nullopt}, *views[k], *calibrated[k],
                                std::nullopt};
    html.sections.push_back({"The views of " + name, "",
                             ViewPictures(at_poses, result.residual_sigma_px,
                                          "cam" + std::to_string(k + 1) + "_", ", " + name)});
  }
  html.sections.push_back({"Report (calibration.txt)", report_text, {}});
  return html;
}

HtmlReport EvaluationHtml(const HeldOutEvaluation& evaluation,
                          const std::vector<CalibrationView>& views, const HousedCamera& camera,
                          const std::string& report_text) {
  std::vector<CalibratedView> calibrated;
  for (const ViewEvaluation& view : evaluation.views) {
    if (!view.evaluated) continue;
    CalibratedView out;
    out.image_name = view.image_name;
    out.cam_from_target = view.cam_from_target;
    out.rms_px = view.rms_px;
    out.num_points = view.num_points;
    calibrated.push_back(out);
  }
  const ViewsAtPoses at_poses{camera, views, calibrated, std::nullopt};
  HtmlReport html{"Held-out evaluation", {}, {}, {}};
  ReportSection section{"The held-out views", "", ViewPictures(at_poses, 0, "", ", held out")};
  const Eigen::MatrixXd length =
      (evaluation.mean_residual_x.array().square() + evaluation.mean_residual_y.array().square())
          .sqrt();
  HeatMapStyle style;
  style.title = "Mean residual per cell: systematic " + FormatFixed(evaluation.systematic_px, 3) +
                " px, noise alone " + FormatFixed(evaluation.noise_floor_px, 3) + " px";
  style.unit = "px";
  section.pictures.push_back(
      {"pattern.png",
       "The length of the residuals' mean in each cell (grey: too few points). Noise alone leaves "
       "it near the noise "
       "floor everywhere; a region well above it is where the calibration is wrong.",
       HeatMapPicture(length.unaryExpr([](double v) { return std::isfinite(v) ? v : -1.0; }),
                      static_cast<int>(camera.camera.width), static_cast<int>(camera.camera.height),
                      style)});
  html.sections.push_back(section);
  html.sections.push_back({"Report (evaluation.txt)", report_text, {}});
  return html;
}

HtmlReport SelfCalibrationHtml(const CalibrationReport& report, const SparseModel& model,
                               const std::string& title) {
  HtmlReport html{title, report.warnings, {}, {}};
  if (report.verdict) html.verdict = HtmlVerdictOf(*report.verdict);
  std::vector<Eigen::Vector3d> points;
  for (const auto& [id, point] : model.points3D) points.push_back(point.xyz);
  std::vector<Rigid3d> poses;
  for (const auto& [id, image] : model.images) poses.push_back(image.cam_from_world);
  html.sections.push_back(
      {"The reconstruction",
       "",
       {{"scene.png",
         "The reconstructed points and the cameras (red, with their axes) from above: a target "
         "that is flat, "
         "cameras where they stood. A bent or scattered scene means the calibration is wrong "
         "however small its RMS.",
         SceneFromAbovePicture(points, poses,
                               "Reconstruction: " + std::to_string(points.size()) + " points, " +
                                   std::to_string(poses.size()) + " images")}}});
  const camera_t camera_id = model.cameras.begin()->first;
  const auto housing = model.housings.find(camera_id);
  const HousedCamera camera{report.camera, housing == model.housings.end()
                                               ? std::nullopt
                                               : std::optional<Housing>(housing->second)};
  std::vector<Eigen::Vector2d> pixels;
  std::vector<PointResidual> residuals;
  int num_images = 0;
  for (const auto& [id, image] : model.images) {
    if (image.camera_id != camera_id) continue;
    for (const Point2D& p : image.points2D) {
      const auto point = model.points3D.find(p.point3D_id);
      if (point == model.points3D.end()) continue;
      pixels.push_back(p.xy);
      const std::optional<Eigen::Vector2d> predicted =
          camera.Project(image.cam_from_world * point->second.xyz);
      if (predicted) residuals.push_back({p.xy, p.xy - *predicted, num_images, false});
    }
    ++num_images;
  }
  ReportSection section{"The observations", "", {}};
  section.pictures.push_back({"coverage.png",
                              "Where the reconstructed points' observations lie over the image.",
                              CoveragePicture(report.camera, pixels, "observations")});
  section.pictures.push_back(
      {"per_view_rms.png", "Each image's RMS reprojection error.",
       PerViewRmsPicture(report.views, report.residual_sigma_px, "Per-image RMS")});
  section.pictures.push_back(
      {"residuals.png",
       "Residual vectors, magnified, one colour per image: a pattern over the image means "
       "the lens or housing model does not fit there.",
       ResidualVectorsPicture(report.camera, residuals, num_images, "Residuals")});
  html.sections.push_back(section);
  if (camera.housing) {
    html.sections.push_back({"The housing",
                             "",
                             {{"housing.png", "The housing to scale, from above and from the side.",
                               HousingPicture(*camera.housing)}}});
  }
  html.sections.push_back({"Report (calibration.txt)", CalibrationReportText(report), {}});
  return html;
}

HtmlReport CrossCheckHtml(const CalibrationReport& portcal,
                          const std::vector<CalibrationView>& views,
                          const std::vector<ReportPicture>& difference_maps,
                          const std::string& report_text) {
  HtmlReport html = CalibrationHtml(portcal, views, "Cross-check against mrcal");
  html.sections.pop_back();  // portcal's calibration.txt: the cross-check's text instead
  html.sections.front().heading = "portcal's calibration of the views (re-solved)";
  html.sections.insert(html.sections.begin(), {"portcal vs mrcal", "", difference_maps});
  html.sections.push_back({"Report (cross_check.txt)", report_text, {}});
  return html;
}

void WriteHtml(const HtmlReport& html, const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir))
    throw InputError(dir.string() + ": cannot create output directory");
  WriteHtmlReport(html, dir);
}

}  // namespace portcal
