#include "model/input_file.hpp"

#include "model/input_error.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>

namespace hamel {

namespace {

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a pipe (FIFO)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The checks on an open descriptor: InputError unless a regular file within the limit; the size.
std::uintmax_t checked_size(int fd, const std::string& path, const std::string& what, std::uintmax_t limit) {
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw InputError(SourceLocation{path, 0, 0}, "", "cannot read the " + what + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw InputError(SourceLocation{path, 0, 0}, "",
                     "the " + what + " is not a regular file (it is " + kind_of(st.st_mode) +
                         "; devices, pipes and folders are refused before anything is read); expected a regular file");
  const std::uintmax_t size = static_cast<std::uintmax_t>(st.st_size);
  if (size > limit)
    throw InputError(SourceLocation{path, 0, 0}, "",
                     "the " + what + " has " + std::to_string(size) + " bytes, more than the limit of " +
                         limit_text(limit) + " for a " + what);
  return size;
}

}  // namespace

std::string limit_text(std::uintmax_t limit) {
  const std::string bytes = std::to_string(limit) + " bytes";
  if (limit >= (std::uintmax_t{1} << 30) && limit % (std::uintmax_t{1} << 30) == 0)
    return bytes + " (" + std::to_string(limit >> 30) + " GiB)";
  if (limit >= (std::uintmax_t{1} << 20) && limit % (std::uintmax_t{1} << 20) == 0)
    return bytes + " (" + std::to_string(limit >> 20) + " MiB)";
  return bytes;
}

InputFile::InputFile(const std::string& path, const std::string& what, std::uintmax_t limit)
    : path_(path), what_(what), limit_(limit) {
  // O_NONBLOCK: opening a FIFO without a writer must not wait for one (it is refused just below).
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd_ < 0)
    throw InputError(SourceLocation{path, 0, 0}, "", "cannot open the " + what + ": " + std::strerror(errno));
  try {
    size_ = checked_size(fd_, path, what, limit);
  } catch (...) {
    ::close(fd_);
    throw;
  }
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags >= 0) ::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t InputFile::fill() {
  if (end_) return 0;
  constexpr std::size_t kBlock = 1 << 16;
  if (begin_ > 0) buffer_.erase(0, begin_), begin_ = 0;
  const std::size_t old = buffer_.size();
  buffer_.resize(old + kBlock);
  ssize_t got;
  do {
    got = ::read(fd_, buffer_.data() + old, kBlock);
  } while (got < 0 && errno == EINTR);
  if (got < 0) {
    const int error = errno;
    buffer_.resize(old);
    throw InputError(SourceLocation{path_, 0, 0}, "", "cannot read the " + what_ + ": " + std::strerror(error));
  }
  buffer_.resize(old + static_cast<std::size_t>(got));
  read_ += static_cast<std::uintmax_t>(got);
  if (read_ > limit_)  // it grew while it was read
    throw InputError(SourceLocation{path_, 0, 0}, "",
                     "the " + what_ + " is larger than the limit of " + limit_text(limit_) + " for a " + what_);
  if (got == 0) end_ = true;
  return static_cast<std::size_t>(got);
}

std::string InputFile::read_all() {
  buffer_.reserve(static_cast<std::size_t>(size_) + (1 << 16));
  while (fill() > 0) {
  }
  std::string out = buffer_.substr(begin_);
  buffer_.clear(), begin_ = 0;
  return out;
}

bool InputFile::next_line(std::string& line) {
  std::size_t from = begin_;  // where the search for '\n' goes on (each byte is searched once)
  for (;;) {
    const std::size_t nl = buffer_.find('\n', from);
    if (nl != std::string::npos) {
      line.assign(buffer_, begin_, nl - begin_);
      begin_ = nl + 1;
      break;
    }
    from = buffer_.size() - begin_;  // fill() moves the unread part to the front
    if (fill() == 0) {
      if (begin_ >= buffer_.size()) return false;
      line.assign(buffer_, begin_, std::string::npos);
      begin_ = buffer_.size();
      break;
    }
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

void check_input_file(const std::string& path, const std::string& what, std::uintmax_t limit) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return;  // missing or unreadable: the reader reports it in its words
  try {
    checked_size(fd, path, what, limit);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

}  // namespace hamel
