#include "scalespace/cli/ProgressBar.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <memory>

namespace scalespace::cli {
namespace {

struct BarState {
  bool terminal = isatty(STDERR_FILENO) != 0;
  std::string stage;
  int lastPercent = -1;
  std::chrono::steady_clock::time_point stageStart = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point lastLine = stageStart;
};

volatile std::sig_atomic_t interrupted = 0;

extern "C" void onInterrupt(int signal) {
  interrupted = signal;
  // A second Ctrl-C ends the program at once, as without a handler.
  std::signal(signal, SIG_DFL);
}

}  // namespace

void cancelOnInterrupt() {
  for (int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, onInterrupt);
}

ProgressCallback makeProgressBar(bool quiet) {
  // Even when quiet, the callback is what lets an interrupt cancel cleanly: the library unwinds
  // and removes its temporary outputs (a killed run would leave NAME.stack.tmp-PID behind).
  if (quiet) return [](double, std::string_view) { return interrupted == 0; };
  auto state = std::make_shared<BarState>();
  return [state](double fraction, std::string_view stage) {
    if (interrupted != 0) {
      if (state->terminal && state->lastPercent >= 0) std::fputc('\n', stderr);
      return false;
    }
    const auto now = std::chrono::steady_clock::now();
    if (state->stage != stage) {
      if (state->terminal && state->lastPercent >= 0) std::fputc('\n', stderr);
      state->stage = std::string(stage);
      state->lastPercent = -1;
      state->stageStart = state->lastLine = now;
    }
    const int percent = int(fraction * 100.0 + 0.5);
    const double elapsed = std::chrono::duration<double>(now - state->stageStart).count();
    if (state->terminal) {
      if (percent == state->lastPercent) return true;
      constexpr int width = 40;
      const int filled = percent * width / 100;
      std::fprintf(stderr, "\r%-12s [%.*s%*s] %3d%% %6.1f s", state->stage.c_str(), filled,
                   "########################################", width - filled, "", percent,
                   elapsed);
      if (percent >= 100) std::fputc('\n', stderr);
      std::fflush(stderr);
    } else {
      // Not a terminal: a line at the start, every 5 s, and at the end.
      const bool due = std::chrono::duration<double>(now - state->lastLine).count() >= 5.0;
      const bool finished = percent >= 100 && state->lastPercent < 100;  // once per stage
      if (state->lastPercent < 0 || finished || (due && percent < 100)) {
        std::fprintf(stderr, "%s: %d%% (%.1f s)\n", state->stage.c_str(), percent, elapsed);
        state->lastLine = now;
      }
    }
    state->lastPercent = percent;
    return true;
  };
}

void reportDone(const std::string& what, std::chrono::steady_clock::time_point start, bool quiet) {
  if (quiet) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr, "%s done in %.2f s\n", what.c_str(), s);
}

}  // namespace scalespace::cli
