// SPDX-License-Identifier: MIT
// Minimal CSV output of simulation samples with lossless number formatting.
#pragma once

#include <charconv>
#include <cstddef>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamel::runtime {

/// Writes rows of doubles as comma-separated lines, one per call of row().
class CsvWriter {
 public:
  /// Writes the header line: the complete column names (the caller includes
  /// "t" if it wants a time column), comma-separated. A name containing a comma,
  /// quote or line break is quoted as RFC 4180 prescribes.
  CsvWriter(std::ostream& os, const std::vector<std::string>& columns) : os_(os), columns_(columns.size()) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (i > 0) {
        os_ << ',';
      }
      write_name(columns[i]);
    }
    os_ << '\n';
  }

  /// Writes one line of n values with 17 significant digits, enough to read
  /// back every double bit for bit. Throws std::invalid_argument when n differs
  /// from the number of columns, since a ragged file would silently misalign
  /// every later column.
  void row(const double* values, std::size_t n) {
    if (n != columns_) {
      throw std::invalid_argument("CsvWriter::row: value count does not match the header");
    }
    // std::to_chars, unlike printf, ignores the C locale, so a decimal comma
    // can never corrupt the file.
    char buffer[32];
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0) {
        os_ << ',';
      }
      const std::to_chars_result r =
          std::to_chars(buffer, buffer + sizeof buffer, values[i], std::chars_format::general, 17);
      os_.write(buffer, r.ptr - buffer);
    }
    os_ << '\n';
  }

 private:
  void write_name(const std::string& name) {
    if (name.find_first_of(",\"\r\n") == std::string::npos) {
      os_ << name;
      return;
    }
    os_ << '"';
    for (const char c : name) {
      if (c == '"') {
        os_ << '"';
      }
      os_ << c;
    }
    os_ << '"';
  }

  std::ostream& os_;
  std::size_t columns_;
};

}  // namespace hamel::runtime
