// The process-wide stop request and the programs' SIGINT / SIGTERM handlers (kelp/sim/stop.hpp).
#include "kelp/sim/stop.hpp"

#include <atomic>
#include <csignal>
#include <utility>

namespace kelp {
namespace sim {

namespace {

// Only lock-free atomics are touched in the handler (async-signal-safe), and any thread may read
// them (kelp-sweep's runs poll from their threads).
std::atomic<bool> requested{false};
std::atomic<int> requested_by{0};
// The signals whose handler install_stop_handlers() installed (a bit each: SIGINT 1, SIGTERM 2).
std::atomic<int> installed{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "the stop request must be lock-free to be set from a signal handler");

extern "C" void on_stop_signal(int signal) {
  request_stop(signal);
  // The second SIGINT or SIGTERM ends the process at once (sigaction is async-signal-safe).
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  const int mine = installed.load(std::memory_order_relaxed);
  if (mine & 1) sigaction(SIGINT, &dfl, nullptr);
  if (mine & 2) sigaction(SIGTERM, &dfl, nullptr);
}

}  // namespace

bool stop_requested() noexcept { return requested.load(std::memory_order_relaxed); }

int stop_signal() noexcept { return requested_by.load(std::memory_order_relaxed); }

void request_stop(int signal) noexcept {
  int none = 0;
  if (signal != 0) requested_by.compare_exchange_strong(none, signal, std::memory_order_relaxed);
  requested.store(true, std::memory_order_relaxed);
}

void clear_stop() noexcept {
  requested.store(false, std::memory_order_relaxed);
  requested_by.store(0, std::memory_order_relaxed);
}

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  // Both signals blocked while the handler runs; interrupted system calls are restarted, so a
  // write of the run's files is not cut short by the first signal.
  sigaddset(&sa.sa_mask, SIGINT);
  sigaddset(&sa.sa_mask, SIGTERM);
  sa.sa_flags = SA_RESTART;
  // A signal the program was started with ignored (`nohup`, a background job's SIGINT) stays
  // ignored, as the shell meant.
  int mine = 0;
  for (const auto& [signal, bit] : {std::pair{SIGINT, 1}, std::pair{SIGTERM, 2}}) {
    struct sigaction old {};
    if (sigaction(signal, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    mine |= bit;
  }
  installed.store(mine, std::memory_order_relaxed);
  if (mine & 1) sigaction(SIGINT, &sa, nullptr);
  if (mine & 2) sigaction(SIGTERM, &sa, nullptr);
}

int interrupted_exit_status() noexcept {
  const int s = stop_signal();
  return 128 + (s > 0 ? s : SIGINT);
}

}  // namespace sim
}  // namespace kelp
