// Feedback on long work: one line on standard error, redrawn in place,
//   walk.bvh: verifying, round 3  [#########.........]  45%  0:37 left
// shown only when standard error is a terminal and not with -q (so never in a pipe, a log or
// the JSON of --json, which goes to standard output), and erased when the work ends so that
// only the command's own output stays on the screen.
#pragma once
#include <chrono>
#include <functional>
#include <mutex>
#include <string>

#include "cli.h"
#include "keyanim/offline/encode.h"

namespace keyanim::cli {

class Progress {
 public:
  // `label` names the work (an input file, a directory); printed as is after escaping.
  Progress(const Globals& g, const std::string& label);
  ~Progress() { erase(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  bool shown() const { return on_; }
  // The work is at `stage` and `fraction` (0 to 1) of the whole is done. Redraws at most ten
  // times a second (always when the stage changes); the time left is estimated from the time
  // taken so far. Safe to call from several threads.
  void update(const std::string& stage, double fraction);
  // Removes the line (before printing anything else to the terminal); the next update draws it
  // again.
  void erase();

 private:
  using Clock = std::chrono::steady_clock;
  bool on_;
  std::string label_;
  std::string stage_;
  bool drawn_ = false;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_{};
  std::mutex mutex_;
};

// The stages of encoding one file as parts of one bar: parsing the BVH, the encoder's own stages
// (error mode: rounds of fitting and verifying until every joint is within the tolerance; their
// number is not known in advance), compressing. The shares and the rounds' model come from one
// thread's wall-clock stage times (a shared 2-core machine: rough) on CMU 01_01 made 44,032
// frames long and on 12 corpus clips: parsing about 3% of the time, the encoder 83% (error
// mode: round 0 a quarter of it, each later round about 0.9 times the one before, 15 to 31
// rounds), compressing 14%. The time left is an estimate: a clip that needs many more rounds
// than usual spends longer near the end.
class EncodeProgress {
 public:
  // No bar (null, or not shown): nothing to do. `then_compress` false: the encoder's stages end
  // the bar (a glTF export has the same stages, and nothing after them worth a share).
  EncodeProgress(Progress* bar, bool error_mode, bool then_compress = true)
      : bar_(bar && bar->shown() ? bar : nullptr), error_mode_(error_mode), end_(then_compress ? 0.86 : 1.0) {}
  // For offline::BvhReadOptions::progress.
  std::function<void(double)> parsing();
  // For offline::EncodeSettings::progress.
  std::function<void(offline::EncodeStage, double)> encoding();
  void compressing();
  void erase() { if (bar_) bar_->erase(); }

 private:
  Progress* bar_;
  bool error_mode_;
  double end_;  // where the encoder's stages end on the bar
  uint32_t round_ = 0;
  offline::EncodeStage last_ = offline::EncodeStage::fitting;
};

}  // namespace keyanim::cli
