// Every file hamel reads, bounded: only regular files (a device such as /dev/zero grew to 2 GB before failing, a
// FIFO blocked forever) and at most a size per kind of file, both refused before anything is read, with the limit
// in the message (docs/errors.md, "Limits"). The file is opened without blocking and checked on the open
// descriptor, so what is read is what was checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace hamel {

/// Limits per kind of input (docs/errors.md, "Limits").
constexpr std::uintmax_t kMaxRobotFileBytes = std::uintmax_t{64} << 20;  ///< URDF, MJCF and every file they include
constexpr std::uintmax_t kMaxTableFileBytes = std::uintmax_t{1} << 30;   ///< CSV tables (--input-file)

/// A file opened for reading after the checks: a regular file of at most `limit` bytes, else InputError naming
/// `path`, what it is (`what`: "robot file", "input file", ...) and the limit.
class InputFile {
 public:
  InputFile(const std::string& path, const std::string& what, std::uintmax_t limit);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  /// The whole file (at most the limit: a file that grows while it is read is refused too).
  std::string read_all();
  /// The next line without its '\n' (and '\r'), false at the end; reads in blocks, so memory stays small.
  bool next_line(std::string& line);
  std::uintmax_t size() const { return size_; }

 private:
  std::size_t fill();  // reads the next block into buffer_; 0 at the end
  std::string path_, what_;
  std::uintmax_t limit_, size_ = 0, read_ = 0;
  int fd_ = -1;
  std::string buffer_;
  std::size_t begin_ = 0;  // unread part of buffer_
  bool end_ = false;
};

/// Only the checks (for files a library opens itself, such as MuJoCo's includes): InputError unless `path` is a
/// regular file of at most `limit` bytes; nothing when it does not exist (the library reports that).
void check_input_file(const std::string& path, const std::string& what, std::uintmax_t limit);

/// A limit as text for messages: "67108864 bytes (64 MiB)".
std::string limit_text(std::uintmax_t limit);

}  // namespace hamel
