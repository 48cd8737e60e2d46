// Housings are centimetres across: a length of a metre or more given for a
// port was meant in millimetres. The port types' UnitMistake say so.
#pragma once

#include <cmath>
#include <optional>
#include <sstream>
#include <string>

namespace portcal {

// "DOMEPORT int_radius = 43.552 m: portcal takes metres (43.552 mm is
// 0.043552 m)" where |value_m| >= 1, else nullopt.
inline std::optional<std::string> LengthInMillimetres(const std::string& port,
                                                      const std::string& name, double value_m) {
  constexpr double kMinMistakenLength = 1.0;
  if (!(std::abs(value_m) >= kMinMistakenLength)) return std::nullopt;
  const auto text = [](double value) {  // 6 significant digits, as typed
    std::ostringstream out;
    out << value;
    return out.str();
  };
  return port + " " + name + " = " + text(value_m) + " m: portcal takes metres (" + text(value_m) +
         " mm is " + text(value_m / 1000) + " m)";
}

}  // namespace portcal
