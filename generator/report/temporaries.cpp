#include "report/temporaries.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

namespace hamel {

namespace {

// The handler may run at any instruction, so the registry is fixed-size, written before it is published
// (`state` goes to 2 last) and read with async-signal-safe calls only (unlink, rmdir, open, getdents64).
constexpr int kSlots = 8;
constexpr std::size_t kPathMax = 4096;
struct Slot {
  std::atomic<int> state{0};  // 0 free, 1 being written, 2 file, 3 folder
  char path[kPathMax];
};
Slot slots[kSlots];

void remove_flat_folder(const char* path) {
  const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buffer[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
      if (n <= 0) break;
      for (long offset = 0; offset < n;) {
        const auto* entry = reinterpret_cast<const struct dirent64*>(buffer + offset);
        offset += entry->d_reclen;
        const char* name = entry->d_name;
        if (std::strcmp(name, ".") == 0 || std::strcmp(name, "..") == 0) continue;
        ::unlinkat(fd, name, 0);
      }
    }
    ::close(fd);
  }
  ::rmdir(path);
}

void remove_registered() {
  for (Slot& s : slots) {
    const int state = s.state.load();
    if (state == 2) ::unlink(s.path);
    if (state == 3) remove_flat_folder(s.path);
  }
}

extern "C" void on_termination_signal(int sig) {
  remove_registered();
  ::_exit(128 + sig);
}

bool process_is_gone(long pid) { return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) == -1 && errno == ESRCH; }

}  // namespace

void install_cleanup_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = on_termination_signal;
  sigemptyset(&action.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&action.sa_mask, sig);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction previous {};
    // A signal ignored by whoever started us (nohup, a shell's background job) stays ignored.
    if (::sigaction(sig, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &action, nullptr);
  }
}

std::string temporary_name_for(const std::string& target) {
  return target + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(std::random_device{}() % 1000000);
}

int register_temporary(const std::string& path, bool is_folder) {
  if (path.size() >= kPathMax) return -1;
  for (int k = 0; k < kSlots; ++k) {
    int expected = 0;
    if (!slots[k].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slots[k].path, path.c_str(), path.size() + 1);
    slots[k].state.store(is_folder ? 3 : 2);
    return k;
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot >= 0 && slot < kSlots) slots[slot].state.store(0);
}

void sweep_stale_temporaries(const std::string& target) {
  namespace fs = std::filesystem;
  const fs::path t(target);
  const std::string base = t.filename().string();
  const fs::path parent = t.has_parent_path() ? t.parent_path() : fs::path(".");
  std::error_code ec;
  fs::directory_iterator it(parent, ec);
  if (ec) return;
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= base.size() + 5 || name.compare(0, base.size(), base) != 0) continue;
    const std::string rest = name.substr(base.size());
    if (rest.compare(0, 5, ".tmp-") != 0 && rest.compare(0, 5, ".old-") != 0) continue;
    // ".tmp-<pid>-<digits>": anything else is not ours (an older hamel wrote ".tmp-<digits>" without a
    // process id, which cannot be told apart from a user's file safely).
    const std::string digits = rest.substr(5);
    const std::size_t dash = digits.find('-');
    if (dash == std::string::npos || dash == 0 || dash + 1 == digits.size()) continue;
    if (digits.find_first_not_of("0123456789-") != std::string::npos || digits.find('-', dash + 1) != std::string::npos)
      continue;
    if (!process_is_gone(std::stol(digits.substr(0, dash)))) continue;
    std::error_code ignored;
    fs::remove_all(entry.path(), ignored);
  }
}

}  // namespace hamel
