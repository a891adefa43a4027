// Output files appear whole or not at all: the text is written to a temporary file next to the target and
// renamed over it, so an interrupted or failed run never leaves a half-written file behind. Targets that are
// not regular files are never replaced: a character device or FIFO (/dev/null, /dev/stdout, a named pipe) is
// written through, a folder or block device is refused, and a symbolic link to a regular file keeps the link
// and replaces the file it points to.
//
// Every output of a run goes through one OutputTransaction (write_file_atomically is a transaction of one file):
// its files are all written and synced to temporaries first and renamed into place only when every one of them
// succeeded, so a run that fails on its second output keeps the first one's old content. An output is refused
// (an InputError, exit 2, before anything is written) when it is empty, a folder, a read-only file, one of the
// run's inputs (note_input_file: the model, scene, --input-file, robot file) or another output of the same run.
#pragma once

#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamel {

/// Writing failed after the output was opened (disk full, I/O error, a closed pipe): not bad input, exit 1.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An output being written: `path` "-" is standard output. Opening problems (a folder, a path that cannot be
/// created) are InputErrors naming `option`; failures while writing or committing are OutputErrors.
class OutputTransaction;

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
  /// commit() in two halves, for a transaction: everything that can fail while writing (flush, sync, close)...
  void prepare();
  /// ...and the rename into place.
  void publish();
  /// What identifies the output's file (its canonical path; empty for standard output and devices).
  const std::string& identity() const { return identity_; }

 private:
  friend class OutputTransaction;
  std::string path_, option_, target_, staging_, identity_;
  std::ofstream file_;
  int slot_ = -1;
  bool to_stdout_ = false;
};

/// All outputs of one run, committed together (see above). Files not committed are removed with the transaction.
class OutputTransaction {
 public:
  /// Opens `path` (named `option` in messages) as one more output; refuses a path another output of the
  /// transaction already names.
  std::ostream& open(const std::string& path, const std::string& option);
  /// Throws OutputError if a write to any output has failed.
  void check();
  /// Prepares every output (flush, sync), and only when all succeeded renames each into place.
  void commit();

 private:
  std::vector<std::unique_ptr<OutputFile>> files_;
};

/// Records `path` as an input of this run (`what`: "the model file", ...): no output may then name it.
void note_input_file(const std::string& path, const std::string& what);

/// Writes `content` to `path` atomically (see OutputFile); `option` names the path in messages.
void write_file_atomically(const std::string& path, const std::string& content, const std::string& option = "");

/// Forces the written contents of the closed file `path` to disk (fsync); false, with errno set, on failure.
bool sync_file(const std::string& path);

/// Flushes standard output and reports whether everything written to it arrived (exit 1 if not).
void flush_stdout_or_throw();

}  // namespace hamel
