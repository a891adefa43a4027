// Output files appear whole or not at all: the text is written to a temporary file next to the target and
// renamed over it, so an interrupted or failed run never leaves a half-written file behind. Targets that are
// not regular files are never replaced: a character device or FIFO (/dev/null, /dev/stdout, a named pipe) is
// written through, a folder or block device is refused, and a symbolic link to a regular file keeps the link
// and replaces the file it points to.
#pragma once

#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

namespace hamel {

/// Writing failed after the output was opened (disk full, I/O error, a closed pipe): not bad input, exit 1.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An output being written: `path` "-" is standard output. Opening problems (a folder, a path that cannot be
/// created) are InputErrors naming `option`; failures while writing or committing are OutputErrors.
class OutputFile {
 public:
  OutputFile(const std::string& path, const std::string& option);
  ~OutputFile();  ///< removes the temporary file unless commit() succeeded
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  std::ostream& stream();
  /// Throws OutputError if a write has already failed (checked by long runs to stop early).
  void check();
  /// Flushes, syncs and closes; a regular target is then renamed into place.
  void commit();

 private:
  std::string path_, option_, target_, staging_;
  std::ofstream file_;
  int slot_ = -1;
  bool to_stdout_ = false;
};

/// Writes `content` to `path` atomically (see OutputFile); `option` names the path in messages.
void write_file_atomically(const std::string& path, const std::string& content, const std::string& option = "");

/// Forces the written contents of the closed file `path` to disk (fsync); false, with errno set, on failure.
bool sync_file(const std::string& path);

/// Flushes standard output and reports whether everything written to it arrived (exit 1 if not).
void flush_stdout_or_throw();

}  // namespace hamel
