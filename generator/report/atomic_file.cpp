#include "report/atomic_file.hpp"

#include "model/input_error.hpp"
#include "report/temporaries.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
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

struct NotedInput {
  std::string path, identity, what;
};
std::vector<NotedInput>& noted_inputs() {
  static std::vector<NotedInput> inputs;
  return inputs;
}

std::string identity_of(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? std::string() : p.string();
}

// Whether `a` and `b` name the same file: the same canonical path, or (hard links) the same inode.
bool same_file(const std::string& a, const std::string& identity_a, const std::string& b,
               const std::string& identity_b) {
  if (!identity_a.empty() && identity_a == identity_b) return true;
  std::error_code ec;
  return fs::equivalent(a, b, ec) && !ec;
}

// A regular file nobody may write: not replaced (a rename would succeed, and leave a writable file).
bool read_only(const std::string& path, const fs::file_status& status) {
  const fs::perms write = fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write;
  return ::access(path.c_str(), W_OK) != 0 || (status.permissions() & write) == fs::perms::none;
}

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
  if (path.empty())
    throw InputError(prefix(option) + "the file name is empty; expected a file name, or - for standard output");
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
  identity_ = identity_of(path);
  for (const NotedInput& input : noted_inputs())
    if (same_file(path, identity_, input.path, input.identity))
      throw InputError(where + " is " + input.what + " of this run; expected another file (an output never replaces " +
                       "an input)");
  if (fs::exists(status) && read_only(target_, status))
    throw InputError(where + " is read-only; expected a file hamel may write (a read-only file is not replaced)");
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
  if (fs::exists(status)) fs::permissions(staging_, status.permissions(), ec);  // the replacement keeps the mode
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
  prepare();
  publish();
}

void OutputFile::prepare() {
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
}

void OutputFile::publish() {
  if (to_stdout_ || staging_.empty()) return;
  std::error_code ec;
  fs::rename(staging_, target_, ec);
  if (ec) throw OutputError("cannot write " + quote(path_) + ": " + ec.message());
  staging_.clear();
}

std::ostream& OutputTransaction::open(const std::string& path, const std::string& option) {
  auto file = std::make_unique<OutputFile>(path, option);
  if (!file->identity().empty())
    for (const auto& other : files_)
      if (same_file(path, file->identity(), other->path_, other->identity()))
        throw InputError(prefix(option) + quote(path) + " is also the output " + other->option_ + " " +
                         quote(other->path_) + "; expected a different file for each output");
  files_.push_back(std::move(file));
  return files_.back()->stream();
}

void OutputTransaction::check() {
  for (const auto& f : files_) f->check();
}

namespace {

// SIGINT, SIGTERM and SIGHUP held back while outputs are renamed into place: the handler (report/temporaries.hpp)
// would exit between two renames and leave some outputs new and some old. They are delivered when this ends.
class TerminationSignalsHeld {
 public:
  TerminationSignalsHeld() {
    sigset_t held;
    sigemptyset(&held);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&held, sig);
    active_ = ::pthread_sigmask(SIG_BLOCK, &held, &previous_) == 0;
  }
  ~TerminationSignalsHeld() {
    if (active_) ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }
  TerminationSignalsHeld(const TerminationSignalsHeld&) = delete;
  TerminationSignalsHeld& operator=(const TerminationSignalsHeld&) = delete;

 private:
  sigset_t previous_;
  bool active_ = false;
};

// A second name for the old content of `target` ("<target>.old-<pid>-<n>", which sweep_stale_temporaries removes
// if a killed run leaves it): a hard link, so `target` itself stays in place; a copy where the file system has no
// hard links. Empty when there is no old file. An OutputError when neither works: nothing has been renamed yet.
std::string keep_old_content(const std::string& target, const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::status(target, ec))) return "";
  std::string aside = temporary_name_for(target);
  aside.replace(target.size(), 5, ".old-");
  if (::link(target.c_str(), aside.c_str()) == 0) return aside;
  const int error = errno;
  if (fs::copy_file(target, aside, ec) && !ec) return aside;
  throw OutputError("cannot write " + quote(path) + ": cannot keep its old content aside for the case another output " +
                    "fails (" + std::strerror(error) + ")");
}

}  // namespace

void OutputTransaction::commit() {
  for (const auto& f : files_) f->prepare();
  if (files_.size() < 2) {
    for (const auto& f : files_) f->publish();
    return;
  }
  // Several files: all or nothing, as far as the file system allows. Each old file gets a second name first; if a
  // rename fails, the outputs already renamed get their old content back (or are removed where there was none).
  const TerminationSignalsHeld held;
  struct Undo {
    OutputFile* file;
    std::string aside;  // the old content's second name, "" if the target did not exist
    bool published = false;
  };
  std::vector<Undo> undo;
  const auto drop_asides = [&undo] {
    for (const Undo& u : undo)
      if (!u.aside.empty()) ::unlink(u.aside.c_str());
  };
  try {
    for (const auto& f : files_)
      undo.push_back({f.get(), f->to_stdout_ || f->staging_.empty() ? "" : keep_old_content(f->target_, f->path_)});
  } catch (...) {
    drop_asides();
    throw;
  }
  for (Undo& u : undo) {
    try {
      u.file->publish();
      u.published = true;
    } catch (const OutputError& e) {
      std::string restored = "; the other files keep their old content";
      for (const Undo& done : undo) {
        if (!done.published || done.file->to_stdout_ || done.file->target_.empty()) continue;
        const std::string& target = done.file->target_;
        const bool ok =
            done.aside.empty() ? ::unlink(target.c_str()) == 0 : ::rename(done.aside.c_str(), target.c_str()) == 0;
        const int error = errno;
        if (!ok) restored = "; restoring " + quote(done.file->path_) + " failed too: " + std::strerror(error);
      }
      drop_asides();
      throw OutputError(e.what() + restored);
    }
  }
  drop_asides();
}

void note_input_file(const std::string& path, const std::string& what) {
  if (path.empty() || path == "-") return;
  noted_inputs().push_back({path, identity_of(path), what});
}

void write_file_atomically(const std::string& path, const std::string& content, const std::string& option) {
  OutputTransaction out;
  out.open(path, option) << content;
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
