#include "app/run/checkpoint.hpp"

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace vdmsim {
namespace {

struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
  }
};

// The value of "key": in a flat JSON object written by write_checkpoint.
std::string field(const std::string& text, const std::string& key) {
  const std::string tag = "\"" + key + "\": ";
  const size_t at = text.find(tag);
  if (at == std::string::npos) return "";
  size_t b = at + tag.size(), e = b;
  if (text[b] == '"') {
    e = text.find('"', b + 1);
    return e == std::string::npos ? "" : text.substr(b + 1, e - b - 1);
  }
  while (e < text.size() && (std::isdigit(static_cast<unsigned char>(text[e])) || text[e] == '-')) ++e;
  return text.substr(b, e - b);
}

}  // namespace

std::string state_hash(const vdm::SimState& s) {
  // Word-wise over the large arrays (the bit patterns of the doubles), byte-wise for the rest.
  Fnv f;
  auto words = [&](const double* p, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      std::uint64_t w;
      std::memcpy(&w, p + i, sizeof w);
      f.h = (f.h ^ w) * 1099511628211ull;
    }
  };
  words(s.u.data(), size_t(s.u.size()));
  words(s.velocity.data(), size_t(s.velocity.size()));
  f.bytes(&s.pressure, sizeof s.pressure);
  f.bytes(&s.step, sizeof s.step);
  f.bytes(&s.time, sizeof s.time);
  return f.hex();
}

std::string run_hash(const std::string& scene_file, const std::string& extra) {
  std::ifstream in(scene_file, std::ios::binary);
  if (!in) return "";
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str() + '\0' + extra;
  Fnv f;
  f.bytes(s.data(), s.size());
  return f.hex();
}

bool write_checkpoint(const std::string& path, const Checkpoint& cp, std::string& error) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << "{\"run_hash\": \"" << cp.run_hash << "\", \"frame\": " << cp.frame << ", \"frames\": " << cp.frames
      << ", \"state_hash\": \"" << cp.state_hash << "\", \"range\": \"" << std::hexfloat << cp.range_lo << ' '
      << cp.range_hi << "\"}\n";
    f.flush();
    if (!f) {
      error = path + ": cannot write the checkpoint (disk full?)";
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    error = path + ": cannot write the checkpoint (" + ec.message() + ")";
    return false;
  }
  return true;
}

bool read_checkpoint(const std::string& path, Checkpoint& cp, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": no checkpoint to resume from (run without --resume first)";
    return false;
  }
  std::stringstream text;
  text << in.rdbuf();
  const std::string t = text.str();
  cp.run_hash = field(t, "run_hash");
  cp.state_hash = field(t, "state_hash");
  const std::string frame = field(t, "frame"), frames = field(t, "frames");
  if (cp.run_hash.empty() || cp.state_hash.empty() || frame.empty() || frames.empty()) {
    error = path + ": not a vdmsim checkpoint";
    return false;
  }
  try {
    cp.frame = std::stoi(frame);
    cp.frames = std::stoi(frames);
    const std::string range = field(t, "range");
    if (!range.empty()) {
      // Written in hexfloat, so that the range is restored bit for bit.
      const size_t space = range.find(' ');
      cp.range_lo = std::strtod(range.substr(0, space).c_str(), nullptr);
      cp.range_hi = std::strtod(range.substr(space + 1).c_str(), nullptr);
    }
  } catch (const std::exception&) {
    error = path + ": not a vdmsim checkpoint (damaged)";
    return false;
  }
  return true;
}

namespace {
constexpr char kStateMagic[8] = {'V', 'D', 'M', 'R', 'U', 'N', 'S', '1'};
}  // namespace

bool write_state_file(const std::string& path, const StateFile& sf, std::string& error) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    const std::int64_t frame = sf.frame, hash_size = static_cast<std::int64_t>(sf.run_hash.size());
    f.write(kStateMagic, sizeof kStateMagic);
    f.write(reinterpret_cast<const char*>(&hash_size), sizeof hash_size);
    f.write(sf.run_hash.data(), static_cast<std::streamsize>(sf.run_hash.size()));
    f.write(reinterpret_cast<const char*>(&frame), sizeof frame);
    f.write(reinterpret_cast<const char*>(&sf.max_volume_error), sizeof sf.max_volume_error);
    f.write(sf.snapshot.data(), static_cast<std::streamsize>(sf.snapshot.size()));
    f.flush();
    if (!f) {
      error = path + ": cannot write the state snapshot (disk full?)";
      std::remove(tmp.c_str());
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = path + ": cannot move the state snapshot into place";
    return false;
  }
  return true;
}

bool read_state_file(const std::string& path, StateFile& sf, std::string& error) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    error = path + ": no state snapshot";
    return false;
  }
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  size_t pos = 0;
  auto take = [&](void* p, size_t n) {
    if (bytes.size() - pos < n) return false;
    std::memcpy(p, bytes.data() + pos, n);
    pos += n;
    return true;
  };
  char magic[sizeof kStateMagic];
  std::int64_t hash_size = 0, frame = 0;
  if (!take(magic, sizeof magic) || std::memcmp(magic, kStateMagic, sizeof magic) != 0 || !take(&hash_size, sizeof hash_size) ||
      hash_size < 0 || hash_size > 64 || bytes.size() - pos < static_cast<size_t>(hash_size)) {
    error = path + ": not a state snapshot";
    return false;
  }
  sf.run_hash.assign(bytes.data() + pos, static_cast<size_t>(hash_size));
  pos += static_cast<size_t>(hash_size);
  if (!take(&frame, sizeof frame) || !take(&sf.max_volume_error, sizeof sf.max_volume_error)) {
    error = path + ": truncated state snapshot";
    return false;
  }
  sf.frame = static_cast<int>(frame);
  sf.snapshot = bytes.substr(pos);
  return true;
}

}  // namespace vdmsim
