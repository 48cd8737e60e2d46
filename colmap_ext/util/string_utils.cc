#include "colmap_ext/util/string_utils.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "colmap_ext/util/error.h"

namespace portcal {

std::string Trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(" \t\r\n");
  return s.substr(begin, end - begin + 1);
}

std::vector<std::string> SplitTokens(const std::string& s, const std::string& delimiters) {
  std::vector<std::string> tokens;
  size_t pos = 0;
  while (pos < s.size()) {
    const size_t begin = s.find_first_not_of(delimiters, pos);
    if (begin == std::string::npos) break;
    size_t end = s.find_first_of(delimiters, begin);
    if (end == std::string::npos) end = s.size();
    tokens.push_back(s.substr(begin, end - begin));
    pos = end;
  }
  return tokens;
}

double ParseDouble(const std::string& token, const std::string& context) {
  const std::string trimmed = Trim(token);
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(trimmed.c_str(), &end);
  if (trimmed.empty() || end != trimmed.c_str() + trimmed.size()) {
    throw InputError(context + ": '" + token + "' is not a number");
  }
  if (!std::isfinite(value)) {
    throw InputError(context + ": '" + token + "' is not finite");
  }
  return value;
}

long long ParseInteger(const std::string& token, const std::string& context, long long min_value,
                       long long max_value) {
  const std::string trimmed = Trim(token);
  char* end = nullptr;
  errno = 0;
  const long long value = std::strtoll(trimmed.c_str(), &end, 10);
  if (trimmed.empty() || end != trimmed.c_str() + trimmed.size() || errno == ERANGE) {
    throw InputError(context + ": '" + token + "' is not an integer");
  }
  if (value < min_value || value > max_value) {
    throw InputError(context + ": " + token + " is outside [" + std::to_string(min_value) + ", " +
                     std::to_string(max_value) + "]");
  }
  return value;
}

std::vector<double> ParseDoubleList(const std::string& s, const std::string& context) {
  std::vector<double> values;
  for (const std::string& token : SplitTokens(s)) {
    values.push_back(ParseDouble(token, context));
  }
  return values;
}

std::string FormatFixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

std::string FormatSignificant(double value, int digits) {
  std::ostringstream out;
  out << std::setprecision(digits) << value;
  return out.str();
}

std::string FormatShortest(double value) {
  // 17 significant digits always read back exactly; the first precision
  // that does is the shortest. Exponents only for the very small or large:
  // 10 reads back from "1e+01" already, but a person expects "10".
  const double magnitude = std::abs(value);
  const bool plain = magnitude >= 1e-4 && magnitude < 1e15;
  for (int digits = 1; digits < 17; ++digits) {
    std::ostringstream out;
    out << std::setprecision(digits) << value;
    if (plain && out.str().find('e') != std::string::npos) continue;
    if (std::strtod(out.str().c_str(), nullptr) == value) return out.str();
  }
  std::ostringstream out;
  out << std::setprecision(17) << value;
  return out.str();
}

std::string YamlQuoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char escaped[5];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", u);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace portcal
