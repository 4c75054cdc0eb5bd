#include "app/run/checkpoint.hpp"

#include "app/run/output_dir.hpp"

#include <algorithm>
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

std::string file_hash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  Fnv f;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) f.bytes(buf, static_cast<size_t>(in.gcount()));
  return f.hex();
}

std::string RunInputs::hash() const {
  Fnv f;
  const std::string t = text();
  f.bytes(t.data(), t.size());
  return f.hex();
}

std::string RunInputs::text() const {
  std::string t;
  for (const auto& [what, h] : items) t += what + "=" + h + ";";
  return t;
}

RunInputs RunInputs::parse(const std::string& text) {
  RunInputs r;
  size_t b = 0;
  while (b < text.size()) {
    const size_t e = text.find(';', b), eq = text.find('=', b);
    if (e == std::string::npos || eq == std::string::npos || eq > e) break;
    r.items.emplace_back(text.substr(b, eq - b), text.substr(eq + 1, e - eq - 1));
    b = e + 1;
  }
  return r;
}

std::vector<std::string> RunInputs::changes_since(const RunInputs& earlier) const {
  std::vector<std::string> out;
  // (Items by name, not structured bindings: clang 14, the fuzz build's, cannot capture those.)
  for (const auto& item : items) {
    const std::string& what = item.first;
    const std::string& h = item.second;
    const auto it = std::find_if(earlier.items.begin(), earlier.items.end(), [&](const auto& e) { return e.first == what; });
    if (it == earlier.items.end()) out.push_back(what + " (not in the interrupted run)");
    else if (it->second != h)
      // A hash says only that the content changed; words (the options) say how.
      out.push_back(what + " changed" +
                    (h.find(' ') != std::string::npos || it->second.find(' ') != std::string::npos
                         ? " (" + it->second + " then, " + h + " now)"
                         : ""));
  }
  for (const auto& item : earlier.items) {
    const std::string& what = item.first;
    if (std::none_of(items.begin(), items.end(), [&](const auto& e) { return e.first == what; }))
      out.push_back(what + " (in the interrupted run, not in this one)");
  }
  return out;
}

bool write_checkpoint(const std::string& path, const Checkpoint& cp, std::string& error) {
  std::ostringstream f;
  f << "{\"run_hash\": \"" << cp.run_hash << "\", \"inputs\": \"" << cp.inputs << "\", \"frame\": " << cp.frame
    << ", \"frames\": " << cp.frames
    << ", \"state_hash\": \"" << cp.state_hash << "\", \"range\": \"" << std::hexfloat << cp.range_lo << ' '
    << cp.range_hi << "\"}\n";
  std::string why;
  if (!write_file_atomically(path, f.str(), why)) {  // (removes its .tmp on failure)
    error = path + ": cannot write the checkpoint (" + why + ")";
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
  cp.inputs = field(t, "inputs");
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
constexpr char kStateMagic[8] = {'V', 'D', 'M', 'R', 'U', 'N', 'S', '2'};
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
    // The checksum of everything before it, last.
    Fnv sum;
    sum.bytes(kStateMagic, sizeof kStateMagic);
    sum.bytes(&hash_size, sizeof hash_size);
    sum.bytes(sf.run_hash.data(), sf.run_hash.size());
    sum.bytes(&frame, sizeof frame);
    sum.bytes(&sf.max_volume_error, sizeof sf.max_volume_error);
    sum.bytes(sf.snapshot.data(), sf.snapshot.size());
    f.write(reinterpret_cast<const char*>(&sum.h), sizeof sum.h);
    f.close();
    if (!f) {
      error = path + ": cannot write the state snapshot (disk full?)";
      std::remove(tmp.c_str());
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = path + ": cannot move the state snapshot into place";
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

bool read_state_file(const std::string& path, StateFile& sf, std::string& error, bool* damaged) {
  if (damaged) *damaged = false;
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    error = path + ": no state snapshot";
    return false;
  }
  std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (damaged) *damaged = true;  // from here on the file is there: any fault is damage
  std::uint64_t stored = 0;
  if (bytes.size() < sizeof stored) {
    error = path + ": truncated state snapshot";
    return false;
  }
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  bytes.resize(bytes.size() - sizeof stored);
  Fnv sum;
  sum.bytes(bytes.data(), bytes.size());
  if (sum.h != stored) {
    error = path + ": the state snapshot's checksum does not match its contents (damaged or changed)";
    return false;
  }
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
  if (damaged) *damaged = false;
  return true;
}

}  // namespace vdmsim
