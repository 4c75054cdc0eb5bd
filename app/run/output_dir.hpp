#pragma once
// The output folder of a run, a study or a generated file, and its files written whole.
#include <filesystem>
#include <string>

namespace vdmsim {

// Creates `dir` (and parents) and checks it can be written (a small probe file, removed again
// whatever happens); false with a message otherwise. `at_run_time`, when given, is set when the
// disk failed (no space left, an I/O error): a failure at run time (exit 1), not a bad path.
bool prepare_output_dir(const std::string& dir, std::string& error, bool* at_run_time = nullptr);

// The folder of the output file `path`, made when missing; where it exists nothing is probed
// (the file may be a device, as /dev/stdout, in a folder the user cannot write). False with
// `error`; `at_run_time` as for prepare_output_dir.
bool prepare_output_file_folder(const std::string& path, std::string& error, bool* at_run_time = nullptr);

// A failed write's errno in words ("no space left on the device" for ENOSPC), and whether it is
// the disk's failure (full, over quota, an I/O error, a file too large) rather than the path's.
std::string write_error_text(int errnum);
bool is_disk_failure(int errnum);

// Whether `path` names `other` or something inside it (when `other` is a folder): through
// another spelling, a symbolic link or a hard link too. Neither needs to exist; what does not
// is compared by its absolute, normalised path. For refusing an output that would overwrite an
// input (compare's --diff, prepare-mesh's --out).
bool is_or_lies_inside(const std::filesystem::path& path, const std::filesystem::path& other);

// Writes `body` to `path` atomically (a temporary file next to it, then a rename), so that a
// reader never sees half a file, nor an interrupted run a torn one. False with `error`.
bool write_file_atomically(const std::filesystem::path& path, const std::string& body, std::string& error);

// A scene's name as a folder name under out/ (a run without --out): every character other than
// letters, digits, '-', '_' and '.' becomes '_', leading dots go (no "..", no hidden or absolute
// path); "scene" when nothing is left.
std::string safe_folder_name(const std::string& name);

// An output folder owned by one run at a time: an exclusive lock on DIR/.vdmsim.lock (flock:
// released when the run ends, however it ends). The file holds the owner's process id.
class OutputLock {
 public:
  OutputLock() = default;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  ~OutputLock();
  // False with a message naming the folder (and the process using it) when another run holds it.
  bool acquire(const std::filesystem::path& dir, std::string& error);

 private:
  int fd_ = -1;
};

}  // namespace vdmsim
