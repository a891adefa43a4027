// SPDX-License-Identifier: MIT
// CsvWriter writes the given header and numbers that parse back to the very same doubles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hamel/runtime/csv.hpp"

namespace {

using hamel::runtime::CsvWriter;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) return fields;
    start = comma + 1;
  }
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(RuntimeCsv, WritesHeaderAndRoundTripsDoublesExactly) {
  const std::vector<double> values = {0.1,
                                      1.0 / 3.0,
                                      -0.0,
                                      std::nextafter(1.0, 2.0),
                                      3.141592653589793,
                                      1e22,
                                      -2.5e-300,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::min(),
                                      std::numeric_limits<double>::max(),
                                      -std::numeric_limits<double>::infinity(),
                                      12345678901234567.0};
  std::ostringstream out;
  CsvWriter csv(out, {"t", "q1", "q2", "q3"});
  ASSERT_EQ(values.size() % 4, 0u);
  for (std::size_t i = 0; i < values.size(); i += 4) csv.row(&values[i], 4);

  std::istringstream in(out.str());
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "t,q1,q2,q3");
  std::size_t k = 0;
  while (std::getline(in, line)) {
    ASSERT_FALSE(line.empty());
    EXPECT_NE(line.back(), ',');
    const std::vector<std::string> fields = split(line);
    ASSERT_EQ(fields.size(), 4u) << line;
    for (const std::string& field : fields) {
      ASSERT_LT(k, values.size());
      char* end = nullptr;
      const double parsed = std::strtod(field.c_str(), &end);
      EXPECT_EQ(*end, '\0') << field;
      EXPECT_TRUE(same_bits(parsed, values[k])) << field << " vs " << values[k];
      ++k;
    }
  }
  EXPECT_EQ(k, values.size());
}

TEST(RuntimeCsv, PrintsSeventeenSignificantDigits) {
  std::ostringstream out;
  CsvWriter csv(out, {"a", "b"});
  const double row[] = {0.1, 2.0};
  csv.row(row, 2);
  EXPECT_EQ(out.str(), "a,b\n0.10000000000000001,2\n");
}

TEST(RuntimeCsv, NaNIsWrittenAsSomethingThatParsesToNaN) {
  std::ostringstream out;
  CsvWriter csv(out, {"x"});
  const double row[] = {std::numeric_limits<double>::quiet_NaN()};
  csv.row(row, 1);
  const std::string text = out.str();
  const std::string field = text.substr(2, text.size() - 3);
  EXPECT_TRUE(std::isnan(std::strtod(field.c_str(), nullptr))) << field;
}

TEST(RuntimeCsv, NamesWithSeparatorsAreQuoted) {
  std::ostringstream out;
  CsvWriter csv(out, {"t", "q,1", "say \"hi\""});
  EXPECT_EQ(out.str(), "t,\"q,1\",\"say \"\"hi\"\"\"\n");
}

TEST(RuntimeCsv, RowWidthMustMatchTheHeader) {
  std::ostringstream out;
  CsvWriter csv(out, {"t", "x"});
  const double row[] = {1.0, 2.0, 3.0};
  EXPECT_THROW(csv.row(row, 3), std::invalid_argument);
  EXPECT_THROW(csv.row(row, 1), std::invalid_argument);
  EXPECT_EQ(out.str(), "t,x\n");
}

}  // namespace
