#include "tools/command_line.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <opencv2/core.hpp>
#include <sstream>

#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "database/lock_wait.h"

namespace po = boost::program_options;

namespace portcal {

CommandLine::CommandLine(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)), options_("Options", 100, 50) {
  options_.add_options()("help,h", "print this help and exit")(
      "log_level", po::value<std::string>(&log_level_)->default_value(log_level_),
      "error | warn | info | debug")(
      "Database.busy_timeout", po::value<double>(&busy_timeout_s_)->default_value(busy_timeout_s_),
      "seconds a database statement waits for another process's lock")(
      "project_path", po::value<std::string>(&project_path_),
      "ini file with the same options (name = value), as in COLMAP; the "
      "command line takes precedence");
}

std::string CommandLine::Help(const std::string& group) const {
  std::ostringstream out;
  out << "Usage: portcal " << command_ << " [options]\n\n" << summary_ << "\n\n";
  if (group.empty()) {
    out << options_;
    return out.str();
  }
  // Only the options of one group: --<group>.*
  po::options_description only(group + " options", 100, 50);
  for (const auto& option : options_.options()) {
    if (option->long_name().rfind(group + ".", 0) == 0) only.add(option);
  }
  if (only.options().empty()) {
    throw UsageError("no option group '" + group + "' (the groups: " + GroupNames() + ")");
  }
  out << only;
  return out.str();
}

std::string CommandLine::GroupNames() const {
  std::vector<std::string> groups;
  for (const auto& option : options_.options()) {
    const std::string& name = option->long_name();
    const size_t dot = name.find('.');
    if (dot == std::string::npos) continue;
    const std::string group = name.substr(0, dot);
    if (std::find(groups.begin(), groups.end(), group) == groups.end()) groups.push_back(group);
  }
  std::string text;
  for (const std::string& group : groups) text += (text.empty() ? "" : ", ") + group;
  return text;
}

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

namespace {

// The group asked for after -h / --help ("portcal camera_calibrator -h
// Calibration"), or "" for all options; nullopt without -h.
std::optional<std::string> HelpRequest(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg != "-h" && arg != "--help") continue;
    if (i + 1 < argc && argv[i + 1][0] != '-') return std::string(argv[i + 1]);
    return std::string();
  }
  return std::nullopt;
}

}  // namespace

std::string CommandLine::Suggestions(std::string name) const {
  while (!name.empty() && name[0] == '-') name.erase(0, 1);
  // Options the name abbreviates, then the same option in another group
  // (--Mask.dictionary: --Markers.dictionary), then those a few typing
  // errors away.
  const auto option_of = [](const std::string& flag) { return flag.substr(flag.find('.') + 1); };
  std::vector<std::pair<size_t, std::string>> ranked;
  for (const auto& option : options_.options()) {
    const std::string& candidate = option->long_name();
    if (candidate.rfind(name, 0) == 0) {
      ranked.emplace_back(0, candidate);
      continue;
    }
    if (name.find('.') != std::string::npos && option_of(candidate) == option_of(name)) {
      ranked.emplace_back(1, candidate);
      continue;
    }
    const size_t distance = EditDistance(name, candidate);
    if (distance <= std::max<size_t>(2, name.size() / 4)) ranked.emplace_back(distance, candidate);
  }
  std::sort(ranked.begin(), ranked.end());
  std::string text;
  for (size_t k = 0; k < ranked.size() && k < 3; ++k)
    text += (k ? ", --" : "--") + ranked[k].second;
  return text;
}

std::string CommandLine::StrayWords(int argc, char** argv) const {
  const po::parsed_options parsed =
      po::command_line_parser(argc, argv).options(options_).allow_unregistered().run();
  std::string words;
  for (const std::string& word : po::collect_unrecognized(parsed.options, po::include_positional)) {
    words += (words.empty() ? "'" : ", '") + word + "'";
  }
  return words;
}

void CommandLine::StoreProjectFile(const std::string& path, po::variables_map* vm) const {
  if (!std::filesystem::is_regular_file(path))
    throw UsageError("--project_path " + path + ": not a file");
  std::ifstream file(path);
  if (!file) throw UsageError("--project_path " + path + ": cannot open");
  try {
    po::store(po::parse_config_file(file, options_), *vm);
  } catch (const po::unknown_option& e) {
    const std::string suggestions = Suggestions(e.get_option_name());
    throw UsageError(path + ": " + e.what() +
                     (suggestions.empty() ? "" : "; did you mean " + suggestions + "?"));
  } catch (const po::error& e) {
    throw UsageError(path + ": " + e.what());
  }
}

bool CommandLine::Parse(int argc, char** argv) {
  if (const std::optional<std::string> group = HelpRequest(argc, argv)) {
    std::cout << Help(*group);
    return false;
  }
  po::variables_map vm;
  try {
    // No guessing: an abbreviated option is an error, not silently the one
    // it happens to abbreviate.
    const int style =
        po::command_line_style::default_style & ~po::command_line_style::allow_guessing;
    // An empty positional description: a stray word is an error, not ignored.
    const po::positional_options_description no_positional;
    po::store(po::command_line_parser(argc, argv)
                  .options(options_)
                  .positional(no_positional)
                  .style(style)
                  .run(),
              vm);
    if (vm.count("project_path")) StoreProjectFile(vm["project_path"].as<std::string>(), &vm);
    po::notify(vm);
  } catch (const po::unknown_option& e) {
    const std::string suggestions = Suggestions(e.get_option_name());
    throw UsageError(std::string(e.what()) +
                     (suggestions.empty() ? "" : "; did you mean " + suggestions + "?") +
                     " (see portcal " + command_ + " -h)");
  } catch (const po::too_many_positional_options_error&) {
    throw UsageError(StrayWords(argc, argv) +
                     ": not an option; options are --name value (see portcal " + command_ + " -h)");
  } catch (const po::error& e) {
    throw UsageError(std::string(e.what()) + " (see portcal " + command_ + " -h)");
  }
  for (const auto& convert : conversions_) convert();
  try {
    SetLogLevel(log_level_);
    SetDatabaseBusyTimeout(busy_timeout_s_);
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
  return true;
}

void CommandLine::AddTriState(const std::string& name, std::optional<bool>* value,
                              const std::string& help) {
  int& raw = ints_.emplace_back(value->has_value() ? static_cast<int>(**value) : -1);
  Add(name, &raw, help);
  conversions_.push_back([name, value, &raw] {
    if (raw < -1 || raw > 1) throw OptionError("--" + name, raw, "-1, 0 or 1");
    *value = raw == -1 ? std::nullopt : std::optional<bool>(raw == 1);
  });
}

void CommandLine::AddRange(const std::string& name, double* low, double* high,
                           const std::string& help) {
  std::string& raw = strings_.emplace_back(FormatShortest(*low) + "," + FormatShortest(*high));
  Add(name, &raw, help);
  conversions_.push_back([name, low, high, &raw] {
    const std::vector<std::string> parts = SplitTokens(raw, ",");
    try {
      size_t used0 = 0, used1 = 0;
      if (parts.size() == 2) {
        const double a = std::stod(parts[0], &used0), b = std::stod(parts[1], &used1);
        if (used0 == parts[0].size() && used1 == parts[1].size() && a <= b) {
          *low = a;
          *high = b;
          return;
        }
      }
    } catch (const std::exception&) {
    }
    throw OptionError("--" + name, raw, "two numbers LOW,HIGH with LOW <= HIGH");
  });
}

void CommandLine::AddHousing(std::optional<Housing>* housing, const std::string& model_help) {
  std::string& model = strings_.emplace_back(housing->has_value() ? (*housing)->ModelName() : "");
  std::string& params = strings_.emplace_back();
  if (housing->has_value()) {
    for (const double v : (*housing)->params)
      params += (params.empty() ? "" : ",") + FormatShortest(v);
  }
  std::string choices;
  for (const std::string& name : SplitTokens(HousingModelNames(), ", ")) choices += name + " | ";
  Add("Housing.model", &model, choices + "NONE: " + model_help);
  Add("Housing.params", &params,
      "the model's parameters, comma separated, metres (FLATPORT: "
      "Nx,Ny,Nz,int_dist,int_thick,na,ng,nw; "
      "DOMEPORT: Cx,Cy,Cz,int_radius,int_thick,na,ng,nw)");
  conversions_.push_back([housing, &model, &params] {
    if (model.empty() || model == "NONE") {
      if (!params.empty())
        throw OptionError("--Housing.params", params, "given together with --Housing.model");
      housing->reset();
      return;
    }
    // The model first: the parameters' meaning depends on it.
    if (!ExistsHousingModelWithName(model))
      throw OptionError("--Housing.model", model, HousingModelNames() + " or NONE");
    if (params.empty())
      throw OptionError("--Housing.params", "''", "the parameters of --Housing.model " + model);
    *housing =
        Housing::FromName(model, ParseDoubleList(params, "--Housing.params"), "--Housing.params");
    (*housing)->ValidateInput("--Housing.params");
  });
}

int ReportErrors(const std::function<void()>& body) {
  try {
    body();
    return kExitSuccess;
  } catch (const UsageError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitUsage;
  } catch (const Cancelled& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitCancelled;
  } catch (const std::bad_alloc&) {
    // Sizes are bounded before work starts; what is left is an input too
    // large for this machine's memory as a whole.
    std::cerr << "error: out of memory: the input (its images, features or sizes) needs more "
                 "memory than this "
                 "machine has; use smaller or fewer images, or a machine with more memory\n";
    return kExitFailure;
  } catch (const cv::Exception& e) {
    // OpenCV's assertion text names its own source, not the input: say
    // that it was OpenCV and keep its reason.
    std::cerr << "error: OpenCV refused the input (" << e.err << " in " << e.func
              << "); an image or a size portcal did not check; please report it with the command\n";
    return kExitFailure;
  } catch (const std::logic_error& e) {
    // A library's bare words (map::at, vector::_M_range_check, stoi) or a
    // failed internal check: never the user's fault alone, so say so.
    std::cerr << "error: internal error (" << e.what()
              << "): a bug, or a damaged input that portcal did not check; please report it with "
                 "the command\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitFailure;
  }
}

}  // namespace portcal
