#include "render/video.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

extern char** environ;

namespace render {

std::string find_program(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::filesystem::path p = std::filesystem::path(dir) / program;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

bool encode_video(const std::string& pattern, double fps, const std::string& output, const std::string& log_path,
                  std::string& error) {
  const std::string ffmpeg = find_program("ffmpeg");
  if (ffmpeg.empty()) {
    error = "ffmpeg is not installed (apt-get install ffmpeg): no video written";
    return false;
  }
  std::ostringstream rate;
  rate << fps;
  std::vector<std::string> args = {ffmpeg,      "-y",       "-loglevel", "error",         "-framerate", rate.str(),
                                   "-i",        pattern,    "-vf",       "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-c:v",      "libx264",  "-preset",   "medium",        "-crf",       "18",
                                   "-pix_fmt",  "yuv420p",  "-movflags", "+faststart",    output};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    error = "could not start " + ffmpeg;
    return false;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      error = "lost track of ffmpeg while writing " + output;
      return false;
    }
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::ifstream log(log_path);
    std::string line, last;
    while (std::getline(log, line))
      if (!line.empty()) last = line;
    error = "ffmpeg failed writing " + output + (last.empty() ? "" : ": " + last) + " (see " + log_path + ")";
    return false;
  }
  std::error_code ec;
  if (std::filesystem::file_size(log_path, ec) == 0) std::filesystem::remove(log_path, ec);
  return true;
}

}  // namespace render
