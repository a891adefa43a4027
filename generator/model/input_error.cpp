#include "model/input_error.hpp"

namespace hamel {

std::string SourceLocation::to_string() const {
  std::string s = file.empty() ? std::string("<input>") : file;
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

static std::string format(const SourceLocation& where, const std::string& key, const std::string& problem) {
  std::string s = where.to_string() + ": error: ";
  if (!key.empty()) s += "'" + key + "': ";
  return s + problem;
}

InputError::InputError(const SourceLocation& where, const std::string& key, const std::string& problem)
    : std::runtime_error(format(where, key, problem)) {}

}  // namespace hamel
