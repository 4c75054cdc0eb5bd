#pragma once
// The programs a sweep starts: its runs (the vdmsim program itself, `vdmsim run ...`) and
// Slurm's commands (sbatch, squeue, scancel).
#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace vdmsim {

// This program's own file (to start runs of the same build).
std::string own_program();

// Starts argv[0] (a path, or a name looked up on PATH) with `argv`, its stdout and stderr
// appended to `log`; in a process group of its own when `own_group` (then a Ctrl-C at the
// terminal reaches only the sweep, which passes it on once). The child is killed (SIGKILL) when
// the thread that started it ends, as when the sweep is killed: call it from the main thread.
// The pid, or -1 with `error`.
pid_t start_process(const std::vector<std::string>& argv, const std::filesystem::path& log, bool own_group,
                    std::string& error);

// A waitpid status as an exit code: the code, or 128 + the signal that ended the process.
int exit_code(int wait_status);

// Runs argv to completion, its stdout and stderr into `output`. The exit code; -1 when it could
// not be started (`output` says why).
int run_program(const std::vector<std::string>& argv, std::string& output);

// `word` quoted for sh ('...').
std::string shell_quote(const std::string& word);

}  // namespace vdmsim
