#include "tools/command_line.h"

#include <fstream>
#include <iostream>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"

namespace po = boost::program_options;

namespace portcal {

CommandLine::CommandLine(std::string command, std::string summary)
    : command_(std::move(command)),
      summary_(std::move(summary)),
      options_("Options", 100, 50) {
  options_.add_options()("help,h", "print this help and exit")(
      "log_level", po::value<std::string>(&log_level_)->default_value(log_level_),
      "error | warn | info | debug")(
      "project_path", po::value<std::string>(&project_path_),
      "ini file with the same options (name = value), as in COLMAP; the "
      "command line takes precedence");
}

std::string CommandLine::Help() const {
  std::ostringstream out;
  out << "Usage: portcal " << command_ << " [options]\n\n" << summary_ << "\n\n"
      << options_;
  return out.str();
}

bool CommandLine::Parse(int argc, char** argv) {
  po::variables_map vm;
  try {
    po::store(po::parse_command_line(argc, argv, options_), vm);
    if (vm.count("help")) {
      std::cout << Help();
      return false;
    }
    if (vm.count("project_path")) {
      const std::string path = vm["project_path"].as<std::string>();
      std::ifstream file(path);
      if (!file) throw InputError("--project_path " + path + ": cannot open");
      po::store(po::parse_config_file(file, options_), vm);
    }
    po::notify(vm);
  } catch (const po::error& e) {
    throw UsageError(std::string(e.what()) + " (see portcal " + command_ + " -h)");
  }
  for (const auto& convert : conversions_) convert();
  try {
    SetLogLevel(log_level_);
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
  return true;
}

void CommandLine::AddTriState(const std::string& name, std::optional<bool>* value, const std::string& help) {
  int& raw = ints_.emplace_back(value->has_value() ? static_cast<int>(**value) : -1);
  Add(name, &raw, help);
  conversions_.push_back([name, value, &raw] {
    if (raw < -1 || raw > 1) throw OptionError("--" + name, std::to_string(raw), "-1, 0 or 1");
    *value = raw == -1 ? std::nullopt : std::optional<bool>(raw == 1);
  });
}

void CommandLine::AddHousing(std::optional<Housing>* housing, const std::string& model_help) {
  std::string& model = strings_.emplace_back(housing->has_value() ? (*housing)->ModelName() : "");
  std::string& params = strings_.emplace_back();
  if (housing->has_value()) {
    for (const double v : (*housing)->params) params += (params.empty() ? "" : ",") + FormatShortest(v);
  }
  Add("Housing.model", &model, "FLATPORT | DOMEPORT | NONE: " + model_help);
  Add("Housing.params", &params,
      "the model's parameters, comma separated, metres (FLATPORT: Nx,Ny,Nz,int_dist,int_thick,na,ng,nw; "
      "DOMEPORT: Cx,Cy,Cz,int_radius,int_thick,na,ng,nw)");
  conversions_.push_back([housing, &model, &params] {
    if (model.empty() || model == "NONE") {
      if (!params.empty()) throw OptionError("--Housing.params", params, "given together with --Housing.model");
      housing->reset();
      return;
    }
    if (params.empty()) throw OptionError("--Housing.params", "''", "the parameters of --Housing.model " + model);
    *housing = Housing::FromName(model, ParseDoubleList(params, "--Housing.params"), "--Housing.params");
  });
}

int ReportErrors(const std::function<void()>& body) {
  try {
    body();
    return kExitSuccess;
  } catch (const UsageError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitUsage;
  } catch (const Cancelled&) {
    std::cerr << "error: cancelled; the database was left as it was\n";
    return kExitCancelled;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitFailure;
  }
}

}  // namespace portcal
