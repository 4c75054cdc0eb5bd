#pragma once
// A C stdio file that closes itself (the image writers' and readers' files).
#include <cstdio>
#include <memory>

namespace render {

struct CFileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};
using CFile = std::unique_ptr<std::FILE, CFileCloser>;

}  // namespace render
