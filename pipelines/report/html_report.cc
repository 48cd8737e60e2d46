#include "pipelines/report/html_report.h"

#include <sstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "pipelines/report/picture.h"

namespace portcal {

namespace {

std::string Escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The text reports wrap (pre-wrap): a long note line scrolled out of sight
// at the right edge.
constexpr const char* kStyle =
    "body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 1em;color:#222}"
    "pre{background:#f4f4f4;padding:.8em;white-space:pre-wrap;overflow-wrap:anywhere;font-size:"
    "13px}"
    "figure{display:inline-block;margin:.5em;vertical-align:top;max-width:100%}"
    "figure img{max-width:100%;border:1px solid #ccc}figcaption{font-size:13px;max-width:960px}"
    ".warning{color:#b00;font-weight:bold}"
    ".verdict{border:2px solid;border-radius:6px;padding:.3em 1em;margin:1em 0}"
    ".verdict p{font-size:20px;font-weight:bold;margin:.3em 0}.verdict ul{margin:.3em "
    "0;padding-left:1.2em}"
    ".verdict li{overflow-wrap:anywhere}"
    ".v-OK{color:#1a7f37;border-color:#1a7f37}.v-CHECK{color:#b35900;border-color:#b35900}"
    ".v-FAIL{color:#b00;border-color:#b00}.verdict li "
    "span{font-weight:bold;display:inline-block;min-width:4.5em}";

// The status is one of three words, used as a class name: anything else
// (a bug) falls back to FAIL's colour.
std::string StatusClass(const std::string& status) {
  return status == "OK" || status == "CHECK" ? "v-" + status : "v-FAIL";
}

}  // namespace

void WriteHtmlReport(const HtmlReport& report, const std::filesystem::path& dir) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" << Escaped(report.title)
       << "</title><style>" << kStyle << "</style></head><body>\n<h1>" << Escaped(report.title)
       << "</h1>\n";
  if (!report.verdict.status.empty()) {
    html << "<div class=\"verdict " << StatusClass(report.verdict.status)
         << "\" id=\"verdict\"><p>Verdict: " << Escaped(report.verdict.status) << "</p><ul>\n";
    for (const HtmlVerdictLine& line : report.verdict.lines) {
      html << "<li class=\"" << StatusClass(line.status) << "\"><span>" << Escaped(line.status)
           << "</span> " << Escaped(line.rule) << ": " << Escaped(line.text) << "</li>\n";
    }
    html << "</ul></div>\n";
  }
  // With a verdict, its lines carry the warnings.
  for (const std::string& warning :
       report.verdict.status.empty() ? report.warnings : std::vector<std::string>()) {
    html << "<p class=\"warning\">WARNING: " << Escaped(warning) << "</p>\n";
  }
  for (const ReportSection& section : report.sections) {
    html << "<h2>" << Escaped(section.heading) << "</h2>\n";
    for (const ReportPicture& picture : section.pictures) {
      if (!picture.image.empty()) {
        WritePng(picture.image, dir / picture.file_name);
      } else if (!std::filesystem::exists(dir / picture.file_name)) {
        throw InputError((dir / picture.file_name).string() +
                         ": a picture of the report is missing");
      }
      html << "<figure><img src=\"" << Escaped(picture.file_name) << "\" alt=\""
           << Escaped(picture.caption) << "\"><figcaption>" << Escaped(picture.caption)
           << "</figcaption></figure>\n";
    }
    if (!section.text.empty()) html << "<pre>" << Escaped(section.text) << "</pre>\n";
  }
  html << "</body></html>\n";
  const std::string page = html.str();
  WriteFileAtomically(dir / "report.html", false, [&](std::ostream& out) { out << page; });
}

}  // namespace portcal
