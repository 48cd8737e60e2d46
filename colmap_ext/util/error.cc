#include "colmap_ext/util/error.h"

namespace portcal {

void ThrowCheckFailure(const char* file, int line, const char* condition,
                       const std::string& message) {
  std::string what = std::string("internal check failed at ") + file + ":" + std::to_string(line) +
                     ": " + condition;
  if (!message.empty()) what += " (" + message + ")";
  throw std::logic_error(what);
}

}  // namespace portcal
