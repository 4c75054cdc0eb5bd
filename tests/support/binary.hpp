#pragma once
// Running the vdmsim binary from tests: to completion with its output, or in the background
// (to be interrupted or killed).
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace vdmsim::test {

struct CliResult {
  int code;
  std::string output;  // stdout and stderr
};

// `binary args` through the shell, to completion.
inline CliResult run_cli(const std::string& binary, const std::string& args) {
  const std::string cmd = binary + " " + args + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe.get())) > 0) out.append(buf.data(), n);
  const int status = pclose(pipe.release());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// Starts args[0] with args, its stdout and stderr going to `log` (discarded by default: a
// test that may fail gives a file, to show what the program said); returns its pid (0 on
// failure).
inline pid_t spawn_quiet(std::vector<std::string> args, const std::string& log = "/dev/null") {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid = 0;
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

// Waits until `path` exists (true) or `seconds` pass (false).
inline bool wait_for_file(const std::filesystem::path& path, int seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  while (!std::filesystem::exists(path)) {
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(seconds)) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

// Once `path` exists (or `seconds` have passed), interrupts `pid` (SIGINT, as Ctrl-C) and
// waits for it to end: its exit code, or -1 when a signal ended it.
inline int interrupt_once_exists(pid_t pid, const std::filesystem::path& path, int seconds) {
  wait_for_file(path, seconds);
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace vdmsim::test
