// report.html: a page a person reads in any browser, offline: the text
// report and the pictures, the PNGs beside it (named in the page, relative
// paths), every file written atomically.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace portcal {

struct ReportPicture {
  std::string file_name;  // e.g. "coverage.png", beside report.html
  std::string caption;    // what to look for
  cv::Mat image;          // empty: the file is already in the folder (written by the stage)
};

struct ReportSection {
  std::string heading;
  std::string text;  // preformatted (the calibration.txt), may be empty
  std::vector<ReportPicture> pictures;
};

// The verdict the page opens with (calibration_verdict.h's, as text).
struct HtmlVerdictLine {
  std::string status;  // "OK", "CHECK", "FAIL"
  std::string rule, text;
};
struct HtmlVerdict {
  std::string status;  // empty: the page has none
  std::vector<HtmlVerdictLine> lines;
};

struct HtmlReport {
  std::string title;
  std::vector<std::string> warnings;  // shown first, in red (after the verdict)
  std::vector<ReportSection> sections;
  HtmlVerdict verdict;
};

// Writes the pictures, then report.html, into `dir` (which exists).
// Throws InputError naming a picture that is neither given nor there.
void WriteHtmlReport(const HtmlReport& report, const std::filesystem::path& dir);

}  // namespace portcal
