#include "render/npy_io.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "render/c_file.hpp"

namespace render {
namespace {

const char kNpyMagic[] = "\x93NUMPY";  // 6 bytes, then the version (1, 0)

// The header's dictionary for a height x width float32 image, padded with spaces and ended
// by a newline so that the data starts at a multiple of 64 bytes (NumPy's alignment).
std::string npy_header(int width, int height) {
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(height) + ", " +
                     std::to_string(width) + "), }";
  const size_t preamble = 6 + 2 + 2;  // magic, version, header length
  const size_t total = (preamble + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - preamble - dict.size() - 1, ' ');
  dict += '\n';
  return dict;
}

// Little-endian bytes of the values, whatever the machine's byte order.
void npy_float_bytes(const std::vector<float>& values, std::vector<unsigned char>& out) {
  out.resize(values.size() * 4);
  for (size_t i = 0; i < values.size(); ++i) {
    std::uint32_t bits;
    std::memcpy(&bits, &values[i], 4);
    for (int b = 0; b < 4; ++b) out[i * 4 + size_t(b)] = static_cast<unsigned char>(bits >> (8 * b));
  }
}

}  // namespace

bool write_npy(const std::string& path, const std::vector<float>& values, int width, int height, std::string& error) {
  namespace fs = std::filesystem;
  if (width <= 0 || height <= 0 || values.size() != size_t(width) * size_t(height)) {
    error = path + ": " + std::to_string(values.size()) + " values for a " + std::to_string(width) + "x" +
            std::to_string(height) + " image";
    return false;
  }
  const std::string header = npy_header(width, height);
  std::vector<unsigned char> data;
  npy_float_bytes(values, data);
  const unsigned char version_and_length[4] = {1, 0, static_cast<unsigned char>(header.size() & 0xff),
                                               static_cast<unsigned char>(header.size() >> 8)};
  const std::string tmp = path + ".tmp";
  bool ok = false;
  {
    CFile f(std::fopen(tmp.c_str(), "wb"));
    if (!f) {
      error = path + ": cannot open for writing";
      return false;
    }
    ok = std::fwrite(kNpyMagic, 1, 6, f.get()) == 6 && std::fwrite(version_and_length, 1, 4, f.get()) == 4 &&
         std::fwrite(header.data(), 1, header.size(), f.get()) == header.size() &&
         std::fwrite(data.data(), 1, data.size(), f.get()) == data.size();
    ok = ok && std::fflush(f.get()) == 0 && !std::ferror(f.get());
    ok = (std::fclose(f.release()) == 0) && ok;
  }
  std::error_code ec;
  if (!ok) {
    fs::remove(tmp, ec);
    error = path + ": writing failed (disk full?)";
    return false;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    error = path + ": cannot rename into place (" + ec.message() + ")";
    return false;
  }
  return true;
}

bool read_npy(const std::string& path, std::vector<float>& values, int& width, int& height, std::string& error) {
  CFile f(std::fopen(path.c_str(), "rb"));
  if (!f) {
    error = path + ": cannot open";
    return false;
  }
  unsigned char pre[10] = {};
  if (std::fread(pre, 1, 10, f.get()) != 10 || std::memcmp(pre, kNpyMagic, 6) != 0 || pre[6] != 1) {
    error = path + ": not a version 1 .npy file";
    return false;
  }
  std::string header(size_t(pre[8]) | (size_t(pre[9]) << 8), '\0');
  if (std::fread(&header[0], 1, header.size(), f.get()) != header.size()) {
    error = path + ": truncated header";
    return false;
  }
  const size_t shape = header.find("'shape': (");
  if (header.find("'descr': '<f4'") == std::string::npos || header.find("'fortran_order': False") == std::string::npos ||
      shape == std::string::npos || std::sscanf(header.c_str() + shape + 10, "%d, %d)", &height, &width) != 2 ||
      width <= 0 || height <= 0) {
    error = path + ": not a 2-D little-endian float32 array in C order";
    return false;
  }
  std::vector<unsigned char> data(size_t(width) * size_t(height) * 4);
  if (std::fread(data.data(), 1, data.size(), f.get()) != data.size()) {
    error = path + ": truncated data";
    return false;
  }
  values.resize(data.size() / 4);
  for (size_t i = 0; i < values.size(); ++i) {
    std::uint32_t bits = 0;
    for (int b = 0; b < 4; ++b) bits |= std::uint32_t(data[i * 4 + size_t(b)]) << (8 * b);
    std::memcpy(&values[i], &bits, 4);
  }
  return true;
}

}  // namespace render
