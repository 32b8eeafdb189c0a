#include "parallel/stop_signals.hpp"

#include <fmt/format.h>

#include <atomic>
#include <csignal>

namespace pwl::app {

namespace {

// Lock-free, so that storing it from a handler is async-signal-safe (a plain sig_atomic_t would
// be, too, but is not safe to read from the other threads).
std::atomic<int> g_received{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void record_stop_signal(int signal) {
  int none = 0;
  g_received.compare_exchange_strong(none, signal);  // the first signal is the one reported
}

constexpr int kSignals[] = {SIGINT, SIGTERM};
struct sigaction g_previous[2];
bool g_installed[2] = {false, false};

}  // namespace

StopSignals::StopSignals() {
  g_received.store(0);
  for (int i = 0; i < 2; ++i) {
    struct sigaction now {};
    g_installed[i] = false;
    if (sigaction(kSignals[i], nullptr, &now) != 0 || now.sa_handler == SIG_IGN) continue;
    struct sigaction handler {};
    handler.sa_handler = record_stop_signal;
    sigemptyset(&handler.sa_mask);
    // One-shot (SA_RESETHAND): the next one acts as if there were no handler. SA_RESTART: a
    // system call it lands in (a read, a wait) goes on rather than failing with EINTR.
    handler.sa_flags = SA_RESETHAND | SA_RESTART;
    g_installed[i] = sigaction(kSignals[i], &handler, &g_previous[i]) == 0;
  }
}

StopSignals::~StopSignals() {
  for (int i = 0; i < 2; ++i) {
    if (g_installed[i]) sigaction(kSignals[i], &g_previous[i], nullptr);
    g_installed[i] = false;
  }
}

int StopSignals::received() { return g_received.load(std::memory_order_relaxed); }

std::string signal_name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return fmt::format("signal {}", signal);
  }
}

}  // namespace pwl::app
