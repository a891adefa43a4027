#include "report/atomic_file.hpp"

#include "model/input_error.hpp"
#include "report/temporaries.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

namespace hamel {

namespace fs = std::filesystem;

namespace {

std::string prefix(const std::string& option) { return option.empty() ? std::string() : option + ": "; }

}  // namespace

// fsync through a second descriptor: std::ofstream does not expose its own.
bool sync_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  return ::close(fd) == 0 && ok;
}

OutputFile::OutputFile(const std::string& path, const std::string& option) : path_(path), option_(option) {
  if (path == "-") {
    to_stdout_ = true;
    return;
  }
  const std::string where = prefix(option) + quote(path);
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_symlink(link) && !fs::exists(status))
    throw InputError(where + " is a symbolic link to nothing; expected a file name");
  if (fs::is_directory(status)) throw InputError(where + " is a folder; expected a file name");
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_character_file(status) && !fs::is_fifo(status))
    throw InputError(where + " is neither a regular file, a character device nor a pipe; expected a file name");
  if (fs::is_character_file(status) || fs::is_fifo(status)) {
    // Write through: replacing /dev/null or a named pipe with a regular file would break them for everyone.
    file_.open(path, std::ios::binary | std::ios::out);
    if (!file_) throw InputError(where + ": cannot write: " + std::strerror(errno));
    return;
  }
  // A link to a regular file: replace the file it points to, keep the link.
  target_ = fs::is_symlink(link) ? fs::canonical(path, ec).string() : path;
  if (target_.empty()) throw InputError(where + ": cannot resolve the symbolic link");
  sweep_stale_temporaries(target_);
  staging_ = temporary_name_for(target_);
  slot_ = register_temporary(staging_, false);
  file_.open(staging_, std::ios::binary | std::ios::out | std::ios::trunc);
  if (!file_) {
    const int error = errno;
    unregister_temporary(slot_);
    slot_ = -1;
    staging_.clear();
    throw InputError(where + ": cannot write: " + std::strerror(error));
  }
}

OutputFile::~OutputFile() {
  if (!staging_.empty()) {
    if (file_.is_open()) file_.close();
    std::error_code ignored;
    fs::remove(staging_, ignored);
  }
  unregister_temporary(slot_);
}

std::ostream& OutputFile::stream() { return to_stdout_ ? std::cout : static_cast<std::ostream&>(file_); }

void OutputFile::check() {
  if (!stream())
    throw OutputError("cannot write " + (to_stdout_ ? std::string("standard output") : quote(path_)) +
                      (errno ? std::string(": ") + std::strerror(errno) : std::string()));
}

void OutputFile::commit() {
  if (to_stdout_) {
    flush_stdout_or_throw();
    return;
  }
  errno = 0;
  file_.flush();
  check();
  file_.close();
  if (!file_) throw OutputError("cannot write " + quote(path_) + ": " + std::strerror(errno ? errno : EIO));
  if (staging_.empty()) return;  // written through
  if (!sync_file(staging_)) throw OutputError("cannot write " + quote(path_) + ": " + std::strerror(errno));
  std::error_code ec;
  fs::rename(staging_, target_, ec);
  if (ec) throw OutputError("cannot write " + quote(path_) + ": " + ec.message());
  staging_.clear();
}

void write_file_atomically(const std::string& path, const std::string& content, const std::string& option) {
  OutputFile out(path, option);
  out.stream() << content;
  out.commit();
}

void flush_stdout_or_throw() {
  errno = 0;
  std::cout.flush();
  const bool stream_ok = static_cast<bool>(std::cout);
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !stream_ok)
    throw OutputError(std::string("cannot write standard output: ") + std::strerror(errno ? errno : EIO));
}

}  // namespace hamel
