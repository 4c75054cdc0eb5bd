#pragma once
// A run's progress on stderr: a bar redrawn in place on a terminal, a line every 10 %
// otherwise.
#include <ostream>
#include <string>

namespace vdmsim {

class Progress {
 public:
  Progress(std::ostream& err, bool terminal) : err_(err), terminal_(terminal) {}
  // `done` of `total` frames of the stage `what` (colour range, replay, render, simulate).
  void show(const std::string& what, int done, int total);
  // The next show() starts a new stage's bar.
  void restart() { last_pct_ = -1; }
  // Ends the bar's line (on a terminal; plain lines end themselves).
  void end_line();

 private:
  std::ostream& err_;
  bool terminal_;
  int last_pct_ = -1;
};

}  // namespace vdmsim
