// Option parsing shared by the subcommands: Boost.Program_options with
// COLMAP's conventions (--Section.option_name, --project_path FILE.ini read
// as the same options, command line first), plus -h and --log_level.
#pragma once

#include <boost/program_options.hpp>
#include <cmath>
#include <functional>
#include <list>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/error.h"
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

// Levenshtein distance, for "did you mean" (options and commands).
size_t EditDistance(const std::string& a, const std::string& b);

class CommandLine {
 public:
  CommandLine(std::string command, std::string summary);

  // Registers --name with *value as default; the parsed value lands there.
  template <typename T>
  void Add(const std::string& name, T* value, const std::string& help) {
    auto* semantic = boost::program_options::value<T>(value);
    if constexpr (std::is_floating_point_v<T>) {
      semantic->default_value(*value, FormatShortest(*value));
      // "nan" and "inf" parse as numbers; no option of portcal means them
      // (each names its "never" or "auto" value in its help).
      semantic->notifier([name](T parsed) {
        if (!std::isfinite(parsed))
          throw OptionError("--" + name, FormatShortest(parsed), "a finite number");
      });
    } else {
      semantic->default_value(*value);
    }
    options_.add_options()(name.c_str(), semantic, help.c_str());
  }
  // Required option without default.
  template <typename T>
  void AddRequired(const std::string& name, T* value, const std::string& help) {
    options_.add_options()(name.c_str(), boost::program_options::value<T>(value)->required(),
                           help.c_str());
  }

  // --name as one of `choices`' names (the value's default shown by name).
  template <typename T>
  void AddChoice(const std::string& name, T* value,
                 const std::vector<std::pair<std::string, T>>& choices, const std::string& help) {
    std::string names, current;
    for (const auto& [choice, v] : choices) {
      names += (names.empty() ? "" : " | ") + choice;
      if (v == *value) current = choice;
    }
    std::string& raw = strings_.emplace_back(current);
    Add(name, &raw, names + ": " + help);
    conversions_.push_back([name, value, choices, names, &raw] {
      for (const auto& [choice, v] : choices) {
        if (choice == raw) {
          *value = v;
          return;
        }
      }
      throw OptionError("--" + name, raw, names);
    });
  }
  // --name as "LOW,HIGH" (two numbers, LOW <= HIGH) into *low and *high.
  void AddRange(const std::string& name, double* low, double* high, const std::string& help);
  // --name as -1 (nullopt: the stage decides), 0 or 1.
  void AddTriState(const std::string& name, std::optional<bool>* value, const std::string& help);
  // --Housing.model and --Housing.params, the same flags and help for every
  // command; after Parse, *housing holds the housing they give (none for an
  // empty model or NONE). `model_help` says what the housing is for here.
  void AddHousing(std::optional<Housing>* housing, const std::string& model_help);

  // Parses argv (argv[0] is the command name). Returns false if help was
  // printed (caller exits 0): -h prints every option, "-h GROUP" those of
  // --GROUP.*. Throws OptionError on bad options, naming them; an unknown or
  // abbreviated option is a UsageError suggesting the options meant.
  bool Parse(int argc, char** argv);

  // The usage, summary and options (only --group.* when group is given;
  // UsageError naming the groups when there is no such group).
  std::string Help(const std::string& group = "") const;

 private:
  // "Calibration, Housing, ..." -- the groups of the --Group.option flags.
  std::string GroupNames() const;
  // Up to three registered options `name` abbreviates or nearly spells.
  std::string Suggestions(std::string name) const;
  // The words of a command line that are no option nor an option's value.
  std::string StrayWords(int argc, char** argv) const;
  // Adds an ini file's options (--project_path); errors name the file.
  void StoreProjectFile(const std::string& path, boost::program_options::variables_map* vm) const;

  std::string command_;
  std::string summary_;
  std::string log_level_ = "info";
  double busy_timeout_s_ = 60;
  std::string project_path_;
  boost::program_options::options_description options_;
  // Conversions of parsed flags into typed fields, run at the end of Parse.
  std::vector<std::function<void()>> conversions_;
  std::list<std::string> strings_;  // raw flag values (stable addresses)
  std::list<int> ints_;
};

// Runs `body`, turning exceptions into one "error: ..." line on stderr and an
// exit code. Returns kExitSuccess if body returns normally.
int ReportErrors(const std::function<void()>& body);

}  // namespace portcal
