// The text helpers every format and message goes through: numbers printed
// so they read back (or to a fixed number of digits), numbers parsed with
// their bounds, YAML names escaped, option errors that print a number as a
// user would type it.
#include "colmap_ext/util/string_utils.h"

#include <gtest/gtest.h>

#include <limits>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

TEST(StringUtils, ShortestReadsBackAndSignificantRounds) {
  EXPECT_EQ(FormatShortest(0.04), "0.04");
  EXPECT_EQ(FormatShortest(1.0 / 3.0), "0.3333333333333333");  // 16 digits read it back
  EXPECT_EQ(FormatShortest(1e-5), "1e-05");
  EXPECT_EQ(FormatShortest(10), "10");  // not "1e+01"
  EXPECT_EQ(FormatShortest(1500), "1500");
  EXPECT_EQ(FormatShortest(-1e300), "-1e+300");
  for (const double v : {0.1 + 0.2, 1.0 / 3.0, 6.02214076e23, -2.5e-12}) {
    EXPECT_EQ(std::stod(FormatShortest(v)), v) << FormatShortest(v);
  }
  EXPECT_EQ(FormatSignificant(1234.5678, 4), "1235");
  EXPECT_EQ(FormatSignificant(0.000123456, 3), "0.000123");
  EXPECT_EQ(FormatSignificant(123456789.0, 3), "1.23e+08");
  EXPECT_EQ(FormatFixed(2.0 / 3.0, 3), "0.667");
}

TEST(StringUtils, ParsedNumbersKeepTheirBoundsAndNameTheContext) {
  EXPECT_EQ(ParseInteger(" 42 ", "n", 0, 100), 42);
  EXPECT_THROW(ParseInteger("101", "n", 0, 100), InputError);
  EXPECT_THROW(ParseInteger("4.5", "n", 0, 100), InputError);
  EXPECT_THROW(ParseDouble("nan", "x"), InputError);
  EXPECT_THROW(ParseDouble("1e999", "x"), InputError);
  try {
    ParseDoubleList("1, 2, three", "--Housing.params");
    ADD_FAILURE() << "a word was read as a number";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--Housing.params"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ParseDoubleList("1.0, 2 3", "x"), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(SplitTokens(",,a, b\t,c,,"), (std::vector<std::string>{"a", "b", "c"}));
}

TEST(StringUtils, YamlQuotedEscapesWhatWouldBreakTheScalar) {
  EXPECT_EQ(YamlQuoted("cam1/img 001.png"), "\"cam1/img 001.png\"");
  EXPECT_EQ(YamlQuoted("a\"b\\c\nd\x01"), "\"a\\\"b\\\\c\\nd\\x01\"");
  EXPECT_EQ(YamlQuoted("\xc3\xa9"), "\"\xc3\xa9\"");  // UTF-8 kept as it is
}

TEST(OptionErrors, PrintANumberAsTheUserWouldTypeIt) {
  EXPECT_STREQ(OptionError("--Calibration.max_num_iterations", 0, ">= 1").what(),
               "option --Calibration.max_num_iterations = 0: expected >= 1");
  EXPECT_STREQ(OptionError("--SiftExtraction.peak_threshold", -1e300, "> 0").what(),
               "option --SiftExtraction.peak_threshold = -1e+300: expected > 0");
  EXPECT_STREQ(OptionError("--x", 0.004, "> 0.01").what(), "option --x = 0.004: expected > 0.01");
  EXPECT_STREQ(OptionError("--x", std::numeric_limits<double>::quiet_NaN(), "a number").what(),
               "option --x = nan: expected a number");
}

}  // namespace
}  // namespace portcal
