// Expressions as text for reports (derive output, error messages).
#pragma once

#include <ginac/ginac.h>

#include <sstream>
#include <string>

namespace hamel {

/// GiNaC's default (parsable) notation of `e`.
inline std::string to_text(const GiNaC::ex& e) {
  std::ostringstream os;
  os << e;
  return os.str();
}

}  // namespace hamel
