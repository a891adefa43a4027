// Errors in user input (model files, command-line values). The CLI maps them to exit status 2;
// every message names the file, line and column, the key and what was expected.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace hamel {

/// Where in an input file something stands (1-based line and column; 0 means unknown).
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
  std::string to_string() const;
};

/// `text` as an error message shows it: in single quotes, control characters escaped (\n, \t,
/// \x1b, ...) so that input cannot forge lines or terminal sequences, and cut after `limit` bytes
/// (at a UTF-8 character boundary, marked by "...").
std::string quote(const std::string& text, std::size_t limit = 80);

/// `text` with control characters, C1 controls and bidirectional overrides escaped as quote() does, without
/// quotes or cutting: for messages that may repeat input (GiNaC's parse errors echo it).
std::string printable(const std::string& text);

/// "a, b, c": names listed in a message.
std::string join(const std::vector<std::string>& words);

/// An error the user can fix in the input. what() is the full, formatted message.
class InputError : public std::runtime_error {
 public:
  /// "file:line:column: error: 'key': problem" (the key quoted as by quote()).
  InputError(const SourceLocation& where, const std::string& key, const std::string& problem);
  explicit InputError(const std::string& message) : std::runtime_error(message), headline_(message) {}
  /// The same with further lines (one problem per line, as when several elements of a file are refused at once):
  /// what() is the message and each note on a line of its own, indented.
  InputError(const SourceLocation& where, const std::string& key, const std::string& problem,
             std::vector<std::string> notes);

  /// The first line (what() without the notes) and the notes: the CLI escapes each (printable) and prints it on
  /// a line of its own, so no input can forge a line.
  const std::string& headline() const { return headline_; }
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  std::string headline_;
  std::vector<std::string> notes_;
};

}  // namespace hamel
