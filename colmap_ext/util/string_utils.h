// Small string helpers for the text formats.
#pragma once

#include <string>
#include <vector>

namespace portcal {

std::string Trim(const std::string& s);
// Splits on any run of the delimiter characters; no empty tokens.
std::vector<std::string> SplitTokens(const std::string& s, const std::string& delimiters = " \t,");
// Parses a finite double; throws InputError("<context>: ...") otherwise.
double ParseDouble(const std::string& token, const std::string& context);
// Parses an integer within [min, max]; throws InputError otherwise.
long long ParseInteger(const std::string& token, const std::string& context, long long min_value,
                       long long max_value);
// "1.0, 2 3" -> {1, 2, 3}; throws InputError naming `context`.
std::vector<double> ParseDoubleList(const std::string& s, const std::string& context);
// `value` with `digits` digits after the point (std::fixed), for reports.
std::string FormatFixed(double value, int digits);
// `value` with `digits` significant digits (as `std::setprecision` alone
// prints it: "1.234e+05" where needed), for messages and labels.
std::string FormatSignificant(double value, int digits);
// The shortest text that reads back as exactly `value` ("0.04", where
// lexical_cast gives "0.040000000000000001"), for help texts and defaults.
std::string FormatShortest(double value);
// `text` as a YAML double-quoted scalar that reads back byte for byte
// (quotes, backslashes and control characters escaped; UTF-8 kept): the
// one form for names (image names may hold any of them) in portcal's YAML.
std::string YamlQuoted(const std::string& text);

}  // namespace portcal
