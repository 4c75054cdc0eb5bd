#pragma once
// Ctrl-C (SIGINT) and SIGTERM during a run: the run stops after the current frame, writes
// everything so far and says "interrupted" in run.json. A second signal stops at once.
namespace vdmsim {

// Installs the handlers for its lifetime and restores the previous ones.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  // The signal received (SIGINT or SIGTERM), 0 while none.
  int received() const;

 private:
  void (*old_int_)(int) = nullptr;
  void (*old_term_)(int) = nullptr;
};

}  // namespace vdmsim
