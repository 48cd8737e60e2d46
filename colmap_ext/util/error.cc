#include "colmap_ext/util/error.h"

#include "colmap_ext/util/string_utils.h"

namespace portcal {

OptionError::OptionError(const std::string& option, double value, const std::string& expected)
    : OptionError(option, FormatShortest(value), expected) {}

void ThrowCheckFailure(const char* file, int line, const char* condition,
                       const std::string& message) {
  std::string what = std::string("internal check failed at ") + file + ":" + std::to_string(line) +
                     ": " + condition;
  if (!message.empty()) what += " (" + message + ")";
  throw std::logic_error(what);
}

}  // namespace portcal
