// Progress of the sample passes on stderr.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>

namespace wp::cli {

// Progress of the sample passes on stderr: on a terminal a bar redrawn after every pass; else
// (a log) one line every `every` seconds. Both give the samples done and requested, the time,
// the ETA (at the pass rate so far; no later than a time limit) and the pixel samples per second.
class Progress {
 public:
  Progress(bool enabled, bool terminal, double every, double pixels,
           std::optional<std::chrono::steady_clock::time_point> deadline)
      : enabled_(enabled),
        terminal_(terminal),
        every_(every),
        pixels_(pixels),
        deadline_(deadline),
        next_line_(every) {}

  // `done` of `total` samples in the film, `rendered` of them by this run (not resumed ones), in
  // `seconds`.
  void update(int done, int total, double seconds, int rendered) {
    if (!enabled_ || (!terminal_ && seconds < next_line_)) return;
    const double rate =
        seconds > 0 ? rendered / seconds : 0.0;  // samples (of every pixel) per second
    double eta = rate > 0 ? (total - done) / rate : 0.0;
    if (deadline_)
      eta = std::min(
          eta,
          std::max(0.0, std::chrono::duration<double>(*deadline_ - std::chrono::steady_clock::now())
                            .count()));
    const double fraction = double(done) / total;
    if (terminal_) {
      char bar[21];
      const int full = static_cast<int>(fraction * 20);
      for (int i = 0; i < 20; ++i) bar[i] = i < full ? '#' : '.';
      bar[20] = 0;
      std::fprintf(stderr, "\r  [%s] %d/%d spp %5.1f%%  %6.1f s  ETA %6.1f s  %.3g samples/s ", bar,
                   done, total, 100.0 * fraction, seconds, eta, rate * pixels_);
      drawn_ = true;
    } else {
      std::fprintf(stderr, "wavepath: %d/%d spp (%.1f%%), %.1f s, ETA %.1f s, %.3g samples/s\n",
                   done, total, 100.0 * fraction, seconds, eta, rate * pixels_);
      if (every_ > 0)  // 0: a line after every pass
        while (next_line_ <= seconds) next_line_ += every_;
    }
    std::fflush(stderr);
  }
  // Ends the terminal's bar line, if one was drawn.
  void finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  bool enabled_, terminal_;
  double every_, pixels_;
  std::optional<std::chrono::steady_clock::time_point> deadline_;
  double next_line_;
  bool drawn_ = false;
};

}  // namespace wp::cli
