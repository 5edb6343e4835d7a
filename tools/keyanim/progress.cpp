#include "progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "escape.h"

namespace keyanim::cli {
namespace {

// Columns of the terminal on standard error: the line must not wrap, or \r would redraw only
// its last part.
size_t terminal_width() {
  winsize w{};
  if (ioctl(STDERR_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col >= 20) return w.ws_col;
  return 80;
}

// "0:37", "12:05", "1:02:03".
std::string duration_text(double seconds) {
  const long s = std::lround(seconds);
  char text[32];
  if (s >= 3600) std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
  return text;
}

}  // namespace

Progress::Progress(const Globals& g, const std::string& label)
    : on_(g.verbosity > 0 && isatty(STDERR_FILENO)), label_(printable(label)) {}

void Progress::update(const std::string& stage, double fraction) {
  if (!on_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const Clock::time_point now = Clock::now();
  fraction = std::clamp(fraction, 0.0, 1.0);
  if (stage == stage_ && drawn_ && now - last_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
  stage_ = stage, last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  std::string left;  // an estimate needs a little of the work done, and some time to measure it
  if (fraction >= 0.02 && fraction < 1.0 && elapsed >= 1.0) left = "  " + duration_text(elapsed * (1.0 - fraction) / fraction) + " left";
  constexpr int kBar = 20;
  const int filled = int(fraction * kBar);
  char percent[8];
  std::snprintf(percent, sizeof percent, "%3d%%", int(fraction * 100.0));
  const std::string tail = "  [" + std::string(size_t(filled), '#') + std::string(size_t(kBar - filled), '.') + "] " +
                           percent + left;
  // The label is cut (from its start: the end of a path says most) to leave room for the rest.
  const size_t width = terminal_width() - 1;
  std::string head = label_ + ": " + stage;
  if (head.size() + tail.size() > width) {
    const size_t keep = width > tail.size() + 4 ? width - tail.size() - 3 : 1;
    head = "..." + head.substr(head.size() > keep ? head.size() - keep : 0);
  }
  const std::string line = "\r" + head + tail + "\033[K";
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::erase() {
  if (!on_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!drawn_) return;
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
  drawn_ = false;
}

// The model of EncodeProgress (progress.h): where each part starts on the bar.
namespace {
constexpr double kEncoderStart = 0.03;
constexpr double kRoundZero = 0.25;  // error mode: round 0's share of the encoder's time
constexpr double kDecay = 0.9;       // each later round's time over the one before
constexpr double kMeasureStart = 0.98;
}  // namespace

std::function<void(double)> EncodeProgress::parsing() {
  if (!bar_) return {};
  return [this](double f) { bar_->update("parsing", f * kEncoderStart); };
}

std::function<void(offline::EncodeStage, double)> EncodeProgress::encoding() {
  if (!bar_) return {};
  return [this](offline::EncodeStage stage, double f) {
    using offline::EncodeStage;
    if (stage == EncodeStage::fitting && last_ == EncodeStage::verifying) ++round_;
    last_ = stage;
    double done;  // of the encoder's time
    std::string name = stage == EncodeStage::fitting ? "fitting" : stage == EncodeStage::verifying ? "verifying" : "measuring";
    if (stage == EncodeStage::measuring) {
      done = kMeasureStart + f * (1.0 - kMeasureStart);
    } else if (!error_mode_) {
      done = f * kMeasureStart;
    } else {
      name += ", round " + std::to_string(round_);
      // Round r spans [start(r), start(r + 1)), its fitting the first half (round 0: 7/8).
      const double later = 1.0 - kRoundZero;
      const auto start = [&](uint32_t r) { return r == 0 ? 0.0 : kRoundZero + later * (1.0 - std::pow(kDecay, r - 1.0)); };
      const double a = start(round_), b = std::min(start(round_ + 1), kMeasureStart);
      const double split = round_ == 0 ? 0.875 : 0.5;
      done = a + (b - a) * (stage == EncodeStage::fitting ? f * split : split + f * (1.0 - split));
    }
    bar_->update(name, kEncoderStart + std::min(done, 1.0) * (end_ - kEncoderStart));
  };
}

void EncodeProgress::compressing() {
  if (bar_) bar_->update("compressing", end_);
}

}  // namespace keyanim::cli
