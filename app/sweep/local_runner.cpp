#include "app/sweep/local_runner.hpp"

#include <signal.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdio>
#include <chrono>
#include <thread>

#include "app/run/stop_signals.hpp"
#include "app/sweep/child_process.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {
namespace {

struct Running {
  size_t job = 0;
  pid_t pid = -1;
  bool resume = false;
  vdm::Clock::time_point start;
};

// The sweep's progress on stderr: redrawn in place on a terminal, a line per run otherwise.
class SweepProgress {
 public:
  SweepProgress(std::ostream& err, const std::string& label, bool terminal, bool quiet, size_t total)
      : err_(err), label_(label), terminal_(terminal), quiet_(quiet), total_(total) {}
  void finished(const RunJob& job, int code, double seconds, size_t running) {
    ++done_;
    if (code != 0) ++failed_;
    if (quiet_) return;
    const std::string what = code == 0 ? "completed" : code == 130 ? "interrupted" : "failed (exit " + std::to_string(code) + ")";
    if (terminal_) {
      show(running);
      return;
    }
    char took[32];
    std::snprintf(took, sizeof took, "%.1f", seconds);
    err_ << label_ << ": " << done_ << "/" << total_ << " " << job.dir.filename().string() << ": " << what << " in " << took
         << " s\n";
  }
  void show(size_t running) {
    if (quiet_ || !terminal_) return;
    err_ << "\r" << label_ << ": " << done_ << "/" << total_ << " runs done" << (failed_ ? ", " + std::to_string(failed_) + " failed" : "")
         << ", " << running << " running   " << std::flush;
  }
  void end() {
    if (!quiet_ && terminal_) err_ << "\n";
  }

 private:
  std::ostream& err_;
  std::string label_;
  bool terminal_, quiet_;
  size_t total_, done_ = 0, failed_ = 0;
};

}  // namespace

int default_parallel() {
  const unsigned n = std::thread::hardware_concurrency();
  return n ? int(n) : 1;
}

bool run_locally(const std::vector<RunJob>& jobs, const JobCommand& command, const LocalRunSettings& settings,
                 std::vector<int>& codes, std::ostream& err) {
  const StopSignals signals;
  codes.assign(jobs.size(), -1);
  std::vector<Running> running;
  SweepProgress progress(err, settings.label, settings.terminal, settings.quiet, jobs.size());
  size_t next = 0;
  bool stopping = false;
  auto start = [&](size_t j, bool resume) {
    const RunJob& job = jobs[j];
    if (!resume) clear_run_results(job.dir);
    std::string error;
    const pid_t pid = start_process(command(job, resume), job.dir / "run.log",
                                    settings.forward_signals, error);
    if (pid < 0) {
      err << "vdmsim: error: " << error << "\n";
      codes[j] = 1;
      return;
    }
    running.push_back({j, pid, resume, vdm::Clock::now()});
  };
  progress.show(0);
  while ((!stopping && next < jobs.size()) || !running.empty()) {
    if (!stopping && signals.received()) {
      stopping = true;
      if (!settings.quiet)
        err << (settings.terminal ? "\n" : "") << settings.label << ": stopping: " << running.size()
            << " running: the " << settings.on_stop << "; `vdmsim " << settings.label << "` again continues\n";
      if (settings.forward_signals)
        for (const Running& r : running) kill(-r.pid, signals.received());
    }
    while (!stopping && next < jobs.size() && int(running.size()) < settings.parallel) {
      start(next, jobs[next].state == RunFolderState::resumable);
      ++next;
      progress.show(running.size());
    }
    bool reaped = false;
    for (size_t k = 0; k < running.size(); ++k) {
      int status = 0;
      const pid_t got = waitpid(running[k].pid, &status, WNOHANG);
      if (got == 0 || (got < 0 && errno == EINTR)) continue;
      const Running r = running[k];
      running.erase(running.begin() + long(k));
      reaped = true;
      const int code = got < 0 ? 1 : exit_code(status);
      // A resume refused (exit 2: the checkpoint or its state no longer fits): afresh.
      if (r.resume && code == 2 && !stopping) {
        start(r.job, false);
        break;
      }
      codes[r.job] = code;
      progress.finished(jobs[r.job], code, vdm::ms_since(r.start) / 1000, running.size());
      break;
    }
    if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  progress.end();
  return !stopping;
}

}  // namespace vdmsim
