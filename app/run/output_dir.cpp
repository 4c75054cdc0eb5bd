#include "app/run/output_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace vdmsim {

std::string write_error_text(int errnum) {
  if (errnum == ENOSPC) return "no space left on the device";
  if (errnum == EDQUOT) return "disk quota exceeded";
  return std::strerror(errnum);
}

bool is_disk_failure(int errnum) { return errnum == ENOSPC || errnum == EDQUOT || errnum == EIO || errnum == EFBIG; }

bool prepare_output_dir(const std::string& dir, std::string& error, bool* at_run_time) {
  namespace fs = std::filesystem;
  if (at_run_time) *at_run_time = false;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    if (at_run_time && ec) *at_run_time = is_disk_failure(ec.value());
    error = dir + ": cannot create the output folder (" +
            (ec ? (ec.value() == ENOSPC ? write_error_text(ENOSPC) : ec.message()) : "not a folder") + ")";
    return false;
  }
  // The probe: written, closed and removed; its errno says why it failed.
  const std::string probe = (fs::path(dir) / ".vdmsim-write-test").string();
  int errnum = 0;
  const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    errnum = errno;
  } else {
    if (write(fd, "ok", 2) != 2) errnum = errno ? errno : EIO;
    if (close(fd) != 0 && errnum == 0) errnum = errno;
    unlink(probe.c_str());
  }
  if (errnum == 0) return true;
  if (at_run_time) *at_run_time = is_disk_failure(errnum);
  error = dir + (is_disk_failure(errnum) ? ": cannot write in the output folder: " + write_error_text(errnum)
                                          : ": the output folder is not writable (" + write_error_text(errnum) + ")");
  return false;
}

bool prepare_output_file_folder(const std::string& path, std::string& error, bool* at_run_time) {
  if (at_run_time) *at_run_time = false;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (parent.empty() || std::filesystem::is_directory(parent, ec)) return true;
  return prepare_output_dir(parent.string(), error, at_run_time);
}

bool is_or_lies_inside(const std::filesystem::path& path, const std::filesystem::path& other) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // Links resolved in the parts that exist; a trailing '/' dropped.
  auto resolved = [&ec](const fs::path& p) {
    fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec).lexically_normal();
    if (r.has_relative_path() && r.filename().empty()) r = r.parent_path();
    return r;
  };
  const fs::path p = resolved(path), o = resolved(other);
  const bool other_exists = fs::exists(o, ec);
  // `path` or one of its folders is `other`: the same names, or (existing) the same file.
  for (fs::path q = p;; q = q.parent_path()) {
    if (q == o) return true;
    std::error_code same;
    if (other_exists && fs::exists(q, same) && fs::equivalent(q, o, same)) return true;
    if (q == q.parent_path() || q.empty()) return false;
  }
}

bool write_file_atomically(const std::filesystem::path& path, const std::string& body, std::string& error) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  std::error_code ec;
  {
    std::ofstream f(tmp, std::ios::binary);
    f << body;
    f.close();  // what close flushes can fail too (a full disk)
    if (!f) {
      error = path.string() + ": write failed (disk full?)";
      std::filesystem::remove(tmp, ec);  // no half-written .tmp left behind
      return false;
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    error = path.string() + ": " + ec.message();
    std::filesystem::remove(tmp, ec);
    return false;
  }
  return true;
}

std::string safe_folder_name(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += (std::isalnum(u) && u < 128) || c == '-' || c == '_' || c == '.' ? c : '_';
  }
  const size_t first = out.find_first_not_of('.');
  out = first == std::string::npos ? "" : out.substr(first);
  return out.empty() ? "scene" : out;
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) close(fd_);  // releases the lock
}

bool OutputLock::acquire(const std::filesystem::path& dir, std::string& error) {
  const std::string path = (dir / ".vdmsim.lock").string();
  const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    error = path + ": cannot create the folder's lock file";
    return false;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char owner[32] = {0};
    const ssize_t n = pread(fd, owner, sizeof owner - 1, 0);
    close(fd);
    error = dir.string() + ": the folder is in use by another vdmsim run" +
            (n > 0 ? std::string(" (process ") + std::string(owner, size_t(n)) + ")" : std::string()) +
            ": wait for it to end or choose another --out";
    return false;
  }
  const std::string pid = std::to_string(getpid());
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
    // The lock holds without the id: only the message of a second run loses it.
  }
  fd_ = fd;
  return true;
}

}  // namespace vdmsim
