#include "report/progress.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

namespace hamel::progress {

namespace {

using Clock = std::chrono::steady_clock;
constexpr auto announce_after = std::chrono::seconds(1);

struct Entry {
  int id;
  std::string what, detail;
  Clock::time_point start;
  bool announced = false;
};

class Reporter {
 public:
  ~Reporter() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (watcher_.joinable()) watcher_.join();
  }

  void set_enabled(bool enabled) {
    std::lock_guard<std::mutex> lock(mutex_);
    enabled_ = enabled;
  }

  bool enabled() {
    std::lock_guard<std::mutex> lock(mutex_);
    return enabled_;
  }

  void say(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (enabled_) std::fprintf(stderr, "hamel: %s ...\n", what.c_str());
  }

  int push(std::string what) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (enabled_ && !watcher_.joinable()) watcher_ = std::thread([this] { watch(); });
    stack_.push_back({next_id_, std::move(what), {}, Clock::now()});
    return next_id_++;
  }

  void detail(int id, std::string text) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (Entry& e : stack_)
      if (e.id == id) e.detail = std::move(text);
  }

  void pop(int id) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t k = stack_.size(); k-- > 0;) {
      if (stack_[k].id != id) continue;
      const Entry& e = stack_[k];
      if (e.announced && enabled_) {
        const double seconds = std::chrono::duration<double>(Clock::now() - e.start).count();
        std::fprintf(stderr, "hamel: %s: done in %.1f s%s%s\n", e.what.c_str(), seconds, e.detail.empty() ? "" : ", ",
                     e.detail.c_str());
      }
      stack_.erase(stack_.begin() + static_cast<std::ptrdiff_t>(k));
      return;
    }
  }

 private:
  void watch() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      wake_.wait_for(lock, std::chrono::milliseconds(100));
      if (!enabled_ || stack_.empty()) continue;
      Entry& e = stack_.back();
      if (e.announced || Clock::now() - e.start < announce_after) continue;
      e.announced = true;
      std::fprintf(stderr, "hamel: %s ...%s%s\n", e.what.c_str(), e.detail.empty() ? "" : " ", e.detail.c_str());
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread watcher_;
  std::vector<Entry> stack_;
  int next_id_ = 0;
  bool enabled_ = true, stop_ = false;
};

Reporter& reporter() {
  static Reporter r;
  return r;
}

}  // namespace

void set_enabled(bool enabled) { reporter().set_enabled(enabled); }
void say(const std::string& what) { reporter().say(what); }
bool enabled() { return reporter().enabled(); }

Step::Step(std::string what) : id_(reporter().push(std::move(what))) {}
Step::~Step() { reporter().pop(id_); }
void Step::detail(std::string text) { reporter().detail(id_, std::move(text)); }

}  // namespace hamel::progress
