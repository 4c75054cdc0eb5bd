#include "app/run/progress.hpp"

#include <iomanip>

namespace vdmsim {

void Progress::show(const std::string& what, int done, int total) {
  const int pct = 100 * done / total;
  if (terminal_) {
    if (pct != last_pct_) {
      const int w = 30, fill = w * done / total;
      err_ << "\r" << what << " [" << std::string(fill, '#') << std::string(w - fill, '.') << "] " << std::setw(3) << pct
           << "%  frame " << done << "/" << total << std::flush;
    }
  } else if (pct / 10 != last_pct_ / 10 || done == total) {
    err_ << what << " frame " << done << "/" << total << " (" << pct << "%)\n";
  }
  last_pct_ = pct;
}

void Progress::end_line() {
  if (terminal_) err_ << "\n";
}

}  // namespace vdmsim
