#include "render/png_io.hpp"

#include <png.h>
#ifdef VDMSIM_HAVE_LIBDEFLATE
#include <libdeflate.h>
#endif

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "render/c_file.hpp"

namespace render {
namespace {

// libpng reports errors by longjmp; the message is kept here for the caller.
void on_error(png_structp png, png_const_charp message) {
  auto* text = static_cast<std::string*>(png_get_error_ptr(png));
  if (text) *text = message;
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

// The channels a PNG file keeps of an RGBA image: RGBA, RGB, or the red channel as grey.
int png_colour_type(int channels) {
  return channels == 4 ? PNG_COLOR_TYPE_RGBA : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY;
}

// Everything that touches setjmp lives in these two functions, with only plain locals.
bool encode(std::FILE* f, const Image& image, int level, int channels, std::vector<std::uint8_t>& row_bytes,
            std::string& msg) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &msg, on_error, on_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, f);
  png_set_compression_level(png, level);
  // At the fast levels no filter: for renders (smooth gradients, flat backgrounds) deflate
  // alone gives files as small as with the Sub filter (720p frames: 235 against 252 kB
  // shaded, 169 against 198 kB stress) in about 0.8x the time; adaptive filtering is much
  // slower.
  png_set_filter(png, 0, level <= 3 ? PNG_FILTER_NONE : PNG_ALL_FILTERS);
  png_set_IHDR(png, info, image.width, image.height, 8, png_colour_type(channels), PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  const size_t w = static_cast<size_t>(image.width);
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t* row = &image.rgba[y * w * 4];
    if (channels == 4) {
      png_write_row(png, row);
    } else {
      for (size_t x = 0; x < w; ++x)
        for (int c = 0; c < channels; ++c) row_bytes[x * size_t(channels) + size_t(c)] = row[x * 4 + size_t(c)];
      png_write_row(png, row_bytes.data());
    }
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

#ifdef VDMSIM_HAVE_LIBDEFLATE
// The fast levels (1-3) without libpng: the rows (filter byte 0, no filter) in one buffer,
// compressed at once by libdeflate (a 720p frame: about 5.6 ms against 9.7 ms for libpng
// with zlib at level 1, and about 13 % smaller), written as IHDR, one IDAT and IEND. The
// buffers are kept per thread (the PNG writer's), so a frame allocates nothing.
void put_u32(std::uint8_t* p, std::uint32_t v) {
  p[0] = std::uint8_t(v >> 24);
  p[1] = std::uint8_t(v >> 16);
  p[2] = std::uint8_t(v >> 8);
  p[3] = std::uint8_t(v);
}

bool put_chunk(std::FILE* f, const char* type, const std::uint8_t* data, size_t size) {
  std::uint8_t head[8], tail[4];
  put_u32(head, std::uint32_t(size));
  std::copy(type, type + 4, head + 4);
  std::uint32_t crc = libdeflate_crc32(0, head + 4, 4);
  if (size > 0) crc = libdeflate_crc32(crc, data, size);  // (a null buffer would restart it)
  put_u32(tail, crc);
  return std::fwrite(head, 1, 8, f) == 8 && (size == 0 || std::fwrite(data, 1, size, f) == size) &&
         std::fwrite(tail, 1, 4, f) == 4;
}

// The PNG rows (filter byte 0, then RGBA, RGB or grey: `channels` 4, 3 or 1) of the w x h
// RGBA pixels into `out`. RGB or grey may be written over the pixels themselves (out == rgba),
// whose buffer is large enough: row y starts at y (1 + 3 w) <= 4 w y, and within a row each
// pixel's bytes land before the next unread pixel; the filter byte goes in once its row is
// moved (in row 0 it is pixel 0's red).
void pack_rows(const std::uint8_t* rgba, size_t w, size_t h, int channels, std::uint8_t* out) {
  const size_t stride = 1 + size_t(channels) * w;
  for (size_t y = 0; y < h; ++y) {
    std::uint8_t* d = out + y * stride + 1;
    const std::uint8_t* s = rgba + y * w * 4;
    if (channels == 4) {
      std::copy(s, s + 4 * w, d);
    } else if (channels == 1) {
      for (size_t x = 0; x < w; ++x) d[x] = s[x * 4];
    } else {
      for (size_t x = 0; x < w; ++x, d += 3, s += 4) {
        const std::uint8_t r = s[0], g = s[1], bl = s[2];
        d[0] = r;
        d[1] = g;
        d[2] = bl;
      }
    }
    out[y * stride] = 0;  // filter: none
  }
}

// `spend`: null, or the image itself when its buffer may be overwritten (RGB or grey only: its
// rows are packed in place).
bool encode_fast(std::FILE* f, const Image& image, Image* spend, int level, int channels, std::string& msg) {
  struct Compressor {
    libdeflate_compressor* c = nullptr;
    int level = -1;
    ~Compressor() {
      if (c) libdeflate_free_compressor(c);
    }
  };
  thread_local Compressor compressor;
  thread_local std::vector<std::uint8_t> raw, packed;
  if (compressor.level != level) {
    if (compressor.c) libdeflate_free_compressor(compressor.c);
    compressor.c = libdeflate_alloc_compressor(level);
    compressor.level = compressor.c ? level : -1;
    if (!compressor.c) {
      msg = "out of memory";
      return false;
    }
  }
  const size_t w = static_cast<size_t>(image.width), h = static_cast<size_t>(image.height);
  const size_t stride = 1 + size_t(channels) * w;
  const std::uint8_t* rows = nullptr;
  if (spend && channels < 4) {  // the rows over the image's own pixels
    pack_rows(spend->rgba.data(), w, h, channels, spend->rgba.data());
    rows = spend->rgba.data();
  } else {
    raw.resize(stride * h);
    pack_rows(image.rgba.data(), w, h, channels, raw.data());
    rows = raw.data();
  }
  // Renders compress to well under a quarter of their raw size: a buffer of that size, and
  // the worst-case bound only for an image that does not fit (compressed again).
  const size_t size = stride * h;
  if (packed.size() < size / 4) packed.resize(size / 4);
  size_t n = libdeflate_zlib_compress(compressor.c, rows, size, packed.data(), packed.size());
  if (n == 0) {
    packed.resize(libdeflate_zlib_compress_bound(compressor.c, size));
    n = libdeflate_zlib_compress(compressor.c, rows, size, packed.data(), packed.size());
  }
  if (n == 0) {
    msg = "compression failed";
    return false;
  }
  static const std::uint8_t signature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  std::uint8_t ihdr[13] = {};
  put_u32(ihdr, std::uint32_t(w));
  put_u32(ihdr + 4, std::uint32_t(h));
  ihdr[8] = 8;                  // bits per channel
  ihdr[9] = channels == 4 ? 6 : channels == 3 ? 2 : 0;  // RGBA, RGB or grey; compression, filter, interlace 0
  return std::fwrite(signature, 1, 8, f) == 8 && put_chunk(f, "IHDR", ihdr, 13) &&
         put_chunk(f, "IDAT", packed.data(), n) && put_chunk(f, "IEND", nullptr, 0);
}
#endif

// What decode() reads after its setjmp: in a function of its own, so that no C++ object of
// the function that called setjmp is created or changed between setjmp and a longjmp
// (-Wclobbered). libpng's errors longjmp out of here only from its own calls, while no
// object of this frame is alive.
bool read_image(png_structp png, png_infop info, Image& image, std::vector<png_bytep>& rows, std::string& msg) {
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (w == 0 || h == 0 || w > 16384 || h > 16384) {
    msg = "unsupported image size " + std::to_string(w) + "x" + std::to_string(h);
    return false;
  }
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  image = Image(static_cast<int>(w), static_cast<int>(h));
  rows.resize(h);
  for (png_uint_32 y = 0; y < h; ++y) rows[y] = &image.rgba[static_cast<size_t>(y) * w * 4];
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  return true;
}

bool decode(std::FILE* f, Image& image, std::vector<png_bytep>& rows, std::string& msg) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &msg, on_error, on_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, f);
  const bool ok = read_image(png, info, image, rows, msg);
  png_destroy_read_struct(&png, &info, nullptr);
  return ok;
}

bool write_file(const std::string& path, const Image& image, Image* spend, int level, int channels, std::string& error) {
  namespace fs = std::filesystem;
  const std::string tmp = path + ".tmp";
  std::string msg;
  bool ok = false;
  {
    CFile f(std::fopen(tmp.c_str(), "wb"));
    if (!f) {
      error = path + ": cannot open for writing";
      return false;
    }
#ifdef VDMSIM_HAVE_LIBDEFLATE
    if (level >= 1 && level <= 3) {
      ok = encode_fast(f.get(), image, spend, level, channels, msg);
    } else
#endif
    {
      std::vector<std::uint8_t> row_bytes(static_cast<size_t>(image.width) * size_t(channels));
      ok = encode(f.get(), image, level, channels, row_bytes, msg);
    }
    ok = ok && std::fflush(f.get()) == 0 && !std::ferror(f.get());
    ok = (std::fclose(f.release()) == 0) && ok;
  }
  std::error_code ec;
  if (!ok) {
    fs::remove(tmp, ec);
    error = path + ": writing failed" + (msg.empty() ? " (disk full?)" : " (" + msg + ")");
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

}  // namespace

bool write_png(const std::string& path, const Image& image, int level, bool alpha, std::string& error) {
  return write_file(path, image, nullptr, level, alpha ? 4 : 3, error);
}

bool write_png_spending(const std::string& path, Image& image, int level, std::string& error) {
  return write_file(path, image, &image, level, 3, error);
}

bool write_grey_png_spending(const std::string& path, Image& image, int level, std::string& error) {
  return write_file(path, image, &image, level, 1, error);
}

bool read_png(const std::string& path, Image& image, std::string& error) {
  CFile f(std::fopen(path.c_str(), "rb"));
  if (!f) {
    error = path + ": cannot open";
    return false;
  }
  unsigned char sig[8] = {};
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8) != 0) {
    error = path + ": not a PNG file";
    return false;
  }
  std::rewind(f.get());
  std::string msg;
  std::vector<png_bytep> rows;
  if (!decode(f.get(), image, rows, msg)) {
    error = path + ": damaged or truncated PNG" + (msg.empty() ? std::string() : " (" + msg + ")");
    return false;
  }
  return true;
}

}  // namespace render
