#include "model/input_error.hpp"

#include <utility>

namespace hamel {

namespace {

// Control characters as escapes (\n, \t, \x1b, ...), also C1 controls (U+0080..U+009F, such as U+009B, a
// terminal's CSI) and bidirectional overrides (U+202A..U+202E, U+2066..U+2069) as \u escapes; everything else
// unchanged.
std::string escape_controls(const std::string& text, std::size_t end) {
  static const char* hex = "0123456789abcdef";
  std::string s;
  for (std::size_t i = 0; i < end; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const unsigned char c1 = i + 1 < end ? static_cast<unsigned char>(text[i + 1]) : 0;
    const unsigned char c2 = i + 2 < end ? static_cast<unsigned char>(text[i + 2]) : 0;
    if (c == 0xc2 && c1 >= 0x80 && c1 <= 0x9f) {
      s += "\\u00";
      s += hex[c1 >> 4];
      s += hex[c1 & 15];
      ++i;
    } else if (c == 0xe2 && ((c1 == 0x80 && c2 >= 0xaa && c2 <= 0xae) || (c1 == 0x81 && c2 >= 0xa6 && c2 <= 0xa9))) {
      const unsigned code = 0x2000u + ((c1 & 0x3fu) << 6) + (c2 & 0x3fu);
      s += "\\u";
      for (int shift = 12; shift >= 0; shift -= 4) s += hex[(code >> shift) & 15];
      i += 2;
    } else if (c == '\n') {
      s += "\\n";
    } else if (c == '\t') {
      s += "\\t";
    } else if (c == '\r') {
      s += "\\r";
    } else if (c < 0x20 || c == 0x7f) {
      s += "\\x";
      s += hex[c >> 4];
      s += hex[c & 15];
    } else {
      s += static_cast<char>(c);
    }
  }
  return s;
}

}  // namespace

std::string SourceLocation::to_string() const {
  std::string s = file.empty() ? std::string("<input>") : escape_controls(file, file.size());
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

std::string printable(const std::string& text) { return escape_controls(text, text.size()); }

std::string join(const std::vector<std::string>& words) {
  std::string s;
  for (const auto& w : words) s += (s.empty() ? "" : ", ") + w;
  return s;
}

std::string quote(const std::string& text, std::size_t limit) {
  std::size_t end = text.size();
  if (end > limit) {
    end = limit;
    while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;  // UTF-8 continuation
  }
  return "'" + escape_controls(text, end) + (end < text.size() ? "...'" : "'");
}

static std::string format(const SourceLocation& where, const std::string& key, const std::string& problem) {
  std::string s = where.to_string() + ": error: ";
  if (!key.empty()) s += quote(key) + ": ";
  return s + problem;
}

InputError::InputError(const SourceLocation& where, const std::string& key, const std::string& problem)
    : std::runtime_error(format(where, key, problem)), headline_(format(where, key, problem)) {}

static std::string with_notes(const std::string& headline, const std::vector<std::string>& notes) {
  std::string s = headline;
  for (const std::string& n : notes) s += "\n  " + n;
  return s;
}

InputError::InputError(const SourceLocation& where, const std::string& key, const std::string& problem,
                       std::vector<std::string> notes)
    : std::runtime_error(with_notes(format(where, key, problem), notes)),
      headline_(format(where, key, problem)),
      notes_(std::move(notes)) {}

}  // namespace hamel
