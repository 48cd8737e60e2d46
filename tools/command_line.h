// Option parsing shared by the subcommands: Boost.Program_options with
// COLMAP's conventions (--Section.option_name, --project_path FILE.ini read
// as the same options, command line first), plus -h and --log_level.
#pragma once

#include <boost/program_options.hpp>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "colmap_ext/util/string_utils.h"

namespace portcal {

constexpr int kExitSuccess = 0;
constexpr int kExitFailure = 1;  // the run failed (bad input, failed solve)
constexpr int kExitUsage = 2;    // bad command line
constexpr int kExitCancelled = 130;

// A command line that cannot be parsed (unknown option, missing value).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CommandLine {
 public:
  CommandLine(std::string command, std::string summary);

  // Registers --name with *value as default; the parsed value lands there.
  template <typename T>
  void Add(const std::string& name, T* value, const std::string& help) {
    auto* semantic = boost::program_options::value<T>(value);
    if constexpr (std::is_floating_point_v<T>) {
      semantic->default_value(*value, FormatShortest(*value));
    } else {
      semantic->default_value(*value);
    }
    options_.add_options()(name.c_str(), semantic, help.c_str());
  }
  // Required option without default.
  template <typename T>
  void AddRequired(const std::string& name, T* value, const std::string& help) {
    options_.add_options()(name.c_str(),
                           boost::program_options::value<T>(value)->required(),
                           help.c_str());
  }

  // Parses argv (argv[0] is the command name). Returns false if help was
  // printed (caller exits 0). Throws OptionError on bad options, naming them.
  bool Parse(int argc, char** argv);

  std::string Help() const;

 private:
  std::string command_;
  std::string summary_;
  std::string log_level_ = "info";
  std::string project_path_;
  boost::program_options::options_description options_;
};

// Runs `body`, turning exceptions into one "error: ..." line on stderr and an
// exit code. Returns kExitSuccess if body returns normally.
int ReportErrors(const std::function<void()>& body);

}  // namespace portcal
