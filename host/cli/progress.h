// Progress of the set-up and the sample passes on stderr.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

namespace wp::cli {

// Progress of the sample passes on stderr: on a terminal a bar redrawn after every pass; else
// (a log) one line every `every` seconds. Both give the samples done and requested, the time,
// the ETA (at the pass rate so far; no later than a time limit) and the pixel samples per second.
// On a terminal, the steps of the set-up before the passes (loading, the BVH, packing and the
// kernels) are shown on the same line with the seconds since the first; a log gets none of them,
// so that a failed run's stderr stays its one error line.
class Progress {
 public:
  Progress(bool enabled, bool terminal, double every, double pixels,
           std::optional<std::chrono::steady_clock::time_point> deadline, FILE* out = stderr)
      : enabled_(enabled),
        terminal_(terminal),
        every_(every),
        pixels_(pixels),
        deadline_(deadline),
        next_line_(every),
        out_(out) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  // A line left open (a step, or a bar of passes cut short by an error) is cleared, so that what
  // follows (the error) starts on a clean line.
  ~Progress() { clear(); }

  // The set-up step now under way, e.g. "loading scene.glb".
  void step(const std::string& what) {
    if (!enabled_ || !terminal_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!setup_start_) setup_start_ = now;
    std::fprintf(out_, "\r\033[K  %6.1f s  %s ...",
                 std::chrono::duration<double>(now - *setup_start_).count(), what.c_str());
    std::fflush(out_);
    open_ = Line::kStep;
  }

  // Clears the terminal's line (a step or a bar), e.g. before warnings are printed.
  void clear() {
    if (open_ == Line::kNone) return;
    std::fprintf(out_, "\r\033[K");
    std::fflush(out_);
    open_ = Line::kNone;
  }

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
      std::fprintf(out_, "\r\033[K  [%s] %d/%d spp %5.1f%%  %6.1f s  ETA %6.1f s  %.3g samples/s ",
                   bar, done, total, 100.0 * fraction, seconds, eta, rate * pixels_);
      open_ = Line::kBar;
    } else {
      std::fprintf(out_, "wavepath: %d/%d spp (%.1f%%), %.1f s, ETA %.1f s, %.3g samples/s\n", done,
                   total, 100.0 * fraction, seconds, eta, rate * pixels_);
      if (every_ > 0)  // 0: a line after every pass
        while (next_line_ <= seconds) next_line_ += every_;
    }
    std::fflush(out_);
  }
  // Ends the terminal's bar line (the bar stays), or clears a step's if no pass was drawn.
  void finish() {
    if (open_ == Line::kBar) {
      std::fprintf(out_, "\n");
      open_ = Line::kNone;
    }
    clear();
  }

 private:
  enum class Line { kNone, kStep, kBar };  // what the terminal's current line shows

  bool enabled_, terminal_;
  double every_, pixels_;
  std::optional<std::chrono::steady_clock::time_point> deadline_;
  double next_line_;
  FILE* out_;
  Line open_ = Line::kNone;
  std::optional<std::chrono::steady_clock::time_point> setup_start_;
};

}  // namespace wp::cli
