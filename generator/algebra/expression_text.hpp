// Expressions as text for reports (derive output, error messages).
#pragma once

#include <ginac/ginac.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace hamel {

/// GiNaC's default (parsable) notation of `e`.
inline std::string to_text(const GiNaC::ex& e) {
  std::ostringstream os;
  os << e;
  return os.str();
}

/// The shortest decimal spelling (15 to 17 significant digits) that reads back as exactly `value`.
inline std::string shortest_decimal(double value) {
  char buf[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  return buf;
}

}  // namespace hamel
