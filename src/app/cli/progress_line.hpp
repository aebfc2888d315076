// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The progress line of validate-geometry on stderr: silent for runs shorter than a second, one
// overwritten line on a terminal, a line per 10% otherwise. The clock and the stream are
// parameters so that tests can drive it (tests/test_cli.cpp).
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <ostream>
#include <streambuf>
#include <string>

namespace asperity::cli {

class ProgressLine {
 public:
  using Clock = std::function<double()>;  ///< seconds since an arbitrary origin

  static double steady_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }

  explicit ProgressLine(bool enabled, std::FILE* out = stderr, bool tty = ::isatty(2) != 0,
                        Clock clock = &ProgressLine::steady_seconds, double quiet_for_s = 1.0, std::string unit = "drops")
      : on_(enabled), tty_(tty), out_(out), clock_(std::move(clock)), quiet_for_(quiet_for_s), start_(clock_()),
        unit_(std::move(unit)) {}

  void operator()(std::uint64_t done, std::uint64_t total) {
    if (!on_ || total == 0) return;
    const double now = clock_(), elapsed = now - start_;
    if (elapsed < quiet_for_) return;  // short runs stay quiet
    const int pct = static_cast<int>(100.0 * double(done) / double(total));
    // Rate and time to go (long streaming runs: hours); "-" before anything is done. Bounce runs:
    // the rate includes the analyses of the variants done, so the ETA is the whole run's share.
    const double rate = double(done) / elapsed;
    char eta[64] = "-";
    if (done > 0 && done < total) std::snprintf(eta, sizeof eta, "%.0f s", double(total - done) / rate);
    else if (done >= total) std::snprintf(eta, sizeof eta, "0 s");
    if (tty_) {
      if (shown_ && now - last_ < 0.25 && done < total) return;
      std::fprintf(out_, "\r  %s: %3d%% (%llu / %llu), %.1f s, %.3g %s/s, ETA %s  ", unit_.c_str(), pct,
                   (unsigned long long)done, (unsigned long long)total, elapsed, rate, unit_.c_str(), eta);
      shown_ = true;
    } else if (pct >= next_pct_) {
      std::fprintf(out_, "  %s: %d%% (%llu / %llu), %.1f s, %.3g %s/s, ETA %s\n", unit_.c_str(), pct,
                   (unsigned long long)done, (unsigned long long)total, elapsed, rate, unit_.c_str(), eta);
      next_pct_ = pct / 10 * 10 + 10;
    }
    last_ = now;
  }
  /// Ends the overwritten line (terminal) so that the next output starts on its own line.
  void finish() {
    if (shown_) std::fprintf(out_, "\n");
    shown_ = false;
  }

  /// An std::ostream for log lines written between progress reports (bounce runs' per-variant
  /// lines): each line first ends the overwritten progress line, so neither garbles the other.
  class Log : private std::streambuf, public std::ostream {
   public:
    explicit Log(ProgressLine& p) : std::ostream(this), p_(p) {}

   private:
    int overflow(int c) override {
      if (c == std::char_traits<char>::eof()) return std::char_traits<char>::not_eof(c);
      if (at_start_) p_.finish();
      at_start_ = c == '\n';
      return std::fputc(c, p_.out_) == EOF ? std::char_traits<char>::eof() : c;
    }
    ProgressLine& p_;
    bool at_start_ = true;
  };

 private:
  bool on_, tty_;
  std::FILE* out_;
  Clock clock_;
  double quiet_for_;
  double start_, last_ = 0;
  std::string unit_;  // what is counted: "drops", or "sequences" for bounce runs
  bool shown_ = false;
  int next_pct_ = 10;
};

}  // namespace asperity::cli
