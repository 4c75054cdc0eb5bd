#include "app/scene/ply_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <vector>

namespace vdmsim {
namespace {

enum class Format { ascii, binary_little_endian, binary_big_endian };

struct TypeInfo {
  const char* name;
  const char* alias;  // the sized spelling (int8, float32, ...)
  int bytes;
  bool integer;
  bool is_signed;
  double lo, hi;  // range of the integer types
};

constexpr TypeInfo kTypes[] = {
    {"char", "int8", 1, true, true, -128.0, 127.0},
    {"uchar", "uint8", 1, true, false, 0.0, 255.0},
    {"short", "int16", 2, true, true, -32768.0, 32767.0},
    {"ushort", "uint16", 2, true, false, 0.0, 65535.0},
    {"int", "int32", 4, true, true, -2147483648.0, 2147483647.0},
    {"uint", "uint32", 4, true, false, 0.0, 4294967295.0},
    {"float", "float32", 4, false, true, 0.0, 0.0},
    {"double", "float64", 8, false, true, 0.0, 0.0},
};

const TypeInfo* find_type(std::string_view name) {
  for (const TypeInfo& t : kTypes)
    if (name == t.name || name == t.alias) return &t;
  return nullptr;
}

// What a property is for this reader.
enum class Role { skip, x, y, z, face_indices };

struct Property {
  std::string name;
  bool list = false;
  const TypeInfo* count = nullptr;  // lists only
  const TypeInfo* value = nullptr;
  Role role = Role::skip;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  long line = 0;
  std::vector<Property> props;
};

// Up to `max` characters of `s`, non-printable bytes shown as '?'.
std::string shown(std::string_view s, size_t max = 60) {
  std::string out;
  for (size_t i = 0; i < s.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    out += std::isprint(c) ? static_cast<char>(c) : '?';
  }
  if (s.size() > max) out += "...";
  return out;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

bool host_is_big_endian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 0;
}

// Reads the items of the data section in either encoding and says where it is for messages.
class DataReader {
 public:
  DataReader(std::string_view bytes, size_t begin, long line, Format format)
      : bytes_(bytes), pos_(begin), line_(line), format_(format),
        swap_((format == Format::binary_big_endian) != host_is_big_endian()) {}

  bool ascii() const { return format_ == Format::ascii; }
  size_t remaining() const { return bytes_.size() - pos_; }

  // Starts item `index` of `element`: ascii moves to its line (blank lines are skipped).
  bool begin_item(const Element& element, std::uint64_t index, std::string& error) {
    element_ = &element;
    index_ = index;
    item_offset_ = pos_;
    if (!ascii()) return true;
    for (;;) {
      if (pos_ >= bytes_.size()) {
        error = where() + ": the file ends here: " + std::to_string(element.count) + " " + element.name +
                " items declared, " + std::to_string(index) + " found (truncated?)";
        return false;
      }
      size_t end = pos_;
      while (end < bytes_.size() && bytes_[end] != '\n') ++end;
      bool blank = true;
      for (size_t i = pos_; i < end; ++i)
        if (!std::isspace(static_cast<unsigned char>(bytes_[i]))) blank = false;
      if (!blank) {
        line_end_ = end;
        return true;
      }
      pos_ = end < bytes_.size() ? end + 1 : end;
      ++line_;
    }
  }

  // Ascii: nothing but blanks may follow the item on its line.
  bool end_item(std::string& error) {
    if (!ascii()) return true;
    skip_blanks();
    if (pos_ < line_end_) {
      error = where() + ": more values than the " + element_->name + " element's properties ('" +
              shown(bytes_.substr(pos_, line_end_ - pos_)) + "')";
      return false;
    }
    pos_ = line_end_ < bytes_.size() ? line_end_ + 1 : line_end_;
    ++line_;
    return true;
  }

  bool value(const TypeInfo& type, double& out, std::string& error) {
    return ascii() ? ascii_value(type, out, error) : binary_value(type, out, error);
  }

  // After the last element: ascii allows only blanks (binary ignores trailing bytes).
  bool finish(std::string& error) {
    if (!ascii()) return true;
    for (; pos_ < bytes_.size(); ++pos_) {
      const char c = bytes_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (!std::isspace(static_cast<unsigned char>(c))) {
        error = "line " + std::to_string(line_) +
                ": data after the last element (the header's element counts are too small?)";
        return false;
      }
    }
    return true;
  }

  std::string where() const {
    std::ostringstream s;
    if (ascii())
      s << "line " << line_ << " (" << element_->name << ' ' << index_ << ')';
    else
      s << element_->name << ' ' << index_ << " (byte offset " << item_offset_ << ')';
    return s.str();
  }

 private:
  void skip_blanks() {
    while (pos_ < line_end_ && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
  }

  bool ascii_value(const TypeInfo& type, double& out, std::string& error) {
    skip_blanks();
    const size_t start = pos_;
    while (pos_ < line_end_ && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    const std::string_view token = bytes_.substr(start, pos_ - start);
    if (token.empty()) {
      error = where() + ": fewer values than the " + element_->name + " element's properties (line cut short?)";
      return false;
    }
    if (type.integer) {
      long long v = 0;
      const auto r = std::from_chars(token.data(), token.data() + token.size(), v);
      if (r.ec != std::errc() || r.ptr != token.data() + token.size()) {
        error = where() + ": '" + shown(token) + "' is not a whole number (type " + type.name + ")";
        return false;
      }
      if (static_cast<double>(v) < type.lo || static_cast<double>(v) > type.hi) {
        error = where() + ": " + std::string(token) + " does not fit the type " + type.name;
        return false;
      }
      out = static_cast<double>(v);
      return true;
    }
    char buf[72];
    if (token.size() >= sizeof buf) {
      error = where() + ": '" + shown(token) + "' is not a number";
      return false;
    }
    std::memcpy(buf, token.data(), token.size());
    buf[token.size()] = '\0';
    char* end = nullptr;
    out = std::strtod(buf, &end);
    if (end != buf + token.size()) {
      error = where() + ": '" + shown(token) + "' is not a number";
      return false;
    }
    if (type.bytes == 4 && std::isfinite(out)) {
      // A float property holds what a float can: values past its range are infinite.
      if (std::fabs(out) > std::numeric_limits<float>::max()) out = out > 0 ? HUGE_VAL : -HUGE_VAL;
    }
    return true;
  }

  bool binary_value(const TypeInfo& type, double& out, std::string& error) {
    const size_t n = static_cast<size_t>(type.bytes);
    if (remaining() < n) {
      error = where() + ": the file ends inside this item (" + std::to_string(remaining()) +
              " bytes left, truncated)";
      return false;
    }
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, n);
    if (swap_) std::reverse(b, b + n);
    pos_ += n;
    switch (n) {
      case 1:
        out = type.is_signed ? static_cast<double>(static_cast<std::int8_t>(b[0])) : static_cast<double>(b[0]);
        return true;
      case 2: {
        std::uint16_t u;
        std::memcpy(&u, b, 2);
        out = type.is_signed ? static_cast<double>(static_cast<std::int16_t>(u)) : static_cast<double>(u);
        return true;
      }
      case 4: {
        if (!type.integer) {
          float f;
          std::memcpy(&f, b, 4);
          out = f;
          return true;
        }
        std::uint32_t u;
        std::memcpy(&u, b, 4);
        out = type.is_signed ? static_cast<double>(static_cast<std::int32_t>(u)) : static_cast<double>(u);
        return true;
      }
      default: {
        std::memcpy(&out, b, 8);
        return true;
      }
    }
  }

  std::string_view bytes_;
  size_t pos_;
  long line_;
  Format format_;
  bool swap_;
  size_t line_end_ = 0;  // ascii: end of the current item's line
  const Element* element_ = nullptr;
  std::uint64_t index_ = 0;
  size_t item_offset_ = 0;
};

// Smallest number of bytes one item of `e` can take after the header (face lists need three
// corners, other lists may be empty; an ascii value is at least a digit and a separator).
std::uint64_t min_item_bytes(const Element& e, bool ascii) {
  std::uint64_t n = 0;
  for (const Property& p : e.props) {
    const std::uint64_t corners = p.role == Role::face_indices ? 3 : 0;
    if (ascii)
      n += p.list ? 2 + 2 * corners : 2;
    else
      n += p.list ? static_cast<std::uint64_t>(p.count->bytes) + corners * static_cast<std::uint64_t>(p.value->bytes)
                  : static_cast<std::uint64_t>(p.value->bytes);
  }
  return n;
}

}  // namespace

bool looks_like_ply(std::string_view head) {
  if (head.size() < 3) return false;
  for (int i = 0; i < 3; ++i)
    if (std::tolower(static_cast<unsigned char>(head[static_cast<size_t>(i)])) != "ply"[i]) return false;
  return head.size() == 3 || head[3] == '\n' || head[3] == '\r';
}

bool parse_ply(std::string_view bytes, vdm::SurfaceMesh& mesh, std::string& error) {
  // --- header ---
  size_t pos = 0;
  long line_no = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= bytes.size()) return false;
    size_t end = pos;
    while (end < bytes.size() && bytes[end] != '\n') ++end;
    line = bytes.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end < bytes.size() ? end + 1 : end;
    ++line_no;
    return true;
  };
  auto fail = [&](const std::string& what) {
    error = "line " + std::to_string(std::max(line_no, 1L)) + ": " + what;
    return false;
  };

  std::string_view line;
  if (!next_line(line) || line != "ply") return fail("not a PLY file: the first line must be 'ply', not '" + shown(line) + "'");
  bool have_format = false;
  Format format = Format::ascii;
  std::vector<Element> elements;
  bool have_end = false;
  while (next_line(line)) {
    const std::vector<std::string_view> w = split(line);
    if (w.empty()) continue;
    const std::string_view key = w[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      if (w.size() != 1) return fail("unexpected words after end_header");
      have_end = true;
      break;
    }
    if (key == "format") {
      if (have_format) return fail("a second format line");
      if (w.size() != 3) return fail("a format line is 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
      if (w[1] == "ascii") format = Format::ascii;
      else if (w[1] == "binary_little_endian") format = Format::binary_little_endian;
      else if (w[1] == "binary_big_endian") format = Format::binary_big_endian;
      else return fail("unsupported format '" + shown(w[1]) + "' (ascii, binary_little_endian or binary_big_endian)");
      if (w[2] != "1.0") return fail("unsupported PLY version '" + shown(w[2]) + "' (1.0 is read)");
      have_format = true;
    } else if (key == "element") {
      if (!have_format) return fail("an element before the format line");
      if (w.size() != 3) return fail("an element line is 'element <name> <count>'");
      Element e;
      e.name = std::string(w[1]);
      e.line = line_no;
      const auto r = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (r.ec != std::errc() || r.ptr != w[2].data() + w[2].size())
        return fail("element '" + shown(w[1]) + "': count '" + shown(w[2]) + "' is not a whole number of items");
      for (const Element& other : elements)
        if (other.name == e.name) return fail("a second element named '" + shown(e.name) + "'");
      elements.push_back(std::move(e));
    } else if (key == "property") {
      if (elements.empty()) return fail("a property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        p.list = true;
        p.count = find_type(w[2]);
        p.value = find_type(w[3]);
        p.name = std::string(w[4]);
        if (!p.count) return fail("unknown list count type '" + shown(w[2]) + "'");
        if (!p.value) return fail("unknown list item type '" + shown(w[3]) + "'");
        if (!p.count->integer) return fail("a list count must have an integer type, not " + std::string(p.count->name));
      } else if (w.size() == 3 && w[1] != "list") {
        p.value = find_type(w[1]);
        p.name = std::string(w[2]);
        if (!p.value) return fail("unknown property type '" + shown(w[1]) + "'");
      } else {
        return fail("a property line is 'property <type> <name>' or 'property list <count type> <item type> <name>'");
      }
      Element& e = elements.back();
      for (const Property& other : e.props)
        if (other.name == p.name) return fail("a second property '" + shown(p.name) + "' in element '" + e.name + "'");
      if (e.name == "vertex") {
        if (p.name == "x" || p.name == "y" || p.name == "z") {
          if (p.list) return fail("vertex property '" + p.name + "' is a list; a coordinate is one number");
          p.role = p.name == "x" ? Role::x : p.name == "y" ? Role::y : Role::z;
        }
      } else if (e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index")) {
        if (!p.list) return fail("face property '" + p.name + "' must be a list of vertex indices");
        if (!p.value->integer) return fail("face vertex indices must have an integer type, not " + std::string(p.value->name));
        for (const Property& other : e.props)
          if (other.role == Role::face_indices) return fail("two vertex index lists in element 'face'");
        p.role = Role::face_indices;
      }
      e.props.push_back(std::move(p));
    } else {
      return fail("unknown header line '" + shown(line) + "'");
    }
  }
  if (!have_end) return fail("the header has no end_header line (truncated or not a PLY file)");
  if (!have_format) return fail("the header has no format line");
  const size_t data_begin = pos;
  const long data_line = line_no + 1;

  // --- what the header declares, checked before anything is allocated ---
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  for (const Element& e : elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name == "face") face = &e;
  }
  auto header_fail = [&](long at, const std::string& what) {
    error = "line " + std::to_string(at) + ": " + what;
    return false;
  };
  if (!vertex) return header_fail(line_no, "the header declares no 'vertex' element");
  if (!face) return header_fail(line_no, "the header declares no 'face' element: the file holds no triangles");
  for (Role r : {Role::x, Role::y, Role::z}) {
    bool found = false;
    for (const Property& p : vertex->props) found = found || p.role == r;
    if (!found)
      return header_fail(vertex->line, std::string("the vertex element has no property '") +
                                           (r == Role::x ? "x" : r == Role::y ? "y" : "z") + "'");
  }
  {
    bool found = false;
    for (const Property& p : face->props) found = found || p.role == Role::face_indices;
    if (!found) return header_fail(face->line, "the face element has no 'vertex_indices' list");
  }
  if (vertex->count > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    return header_fail(vertex->line, "more vertices than this reader can index (" + std::to_string(vertex->count) + ")");
  const bool ascii = format == Format::ascii;
  // An ascii file's last value may end the file without a separator: one byte of slack.
  std::uint64_t budget = static_cast<std::uint64_t>(bytes.size() - data_begin) + (ascii ? 1 : 0);
  for (const Element& e : elements) {
    if (e.count == 0) continue;
    if (e.props.empty()) return header_fail(e.line, "element '" + shown(e.name) + "' has items but no properties");
    const std::uint64_t each = min_item_bytes(e, ascii);
    if (e.count > budget / each) {
      std::ostringstream s;
      s << "element '" << shown(e.name) << "' declares " << e.count << " items of at least " << each
        << " bytes each, more than the " << bytes.size() - data_begin
        << " bytes after the header can hold: truncated or corrupt";
      return header_fail(e.line, s.str());
    }
    budget -= e.count * each;
  }

  // --- data ---
  DataReader in(bytes, data_begin, data_line, format);
  std::vector<vdm::Vec3> points(static_cast<size_t>(vertex->count), vdm::Vec3::Zero());
  std::vector<std::array<int, 3>> tris;
  std::vector<int> corners;
  const double vertex_count = static_cast<double>(vertex->count);
  for (const Element& e : elements) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      if (!in.begin_item(e, i, error)) return false;
      for (const Property& p : e.props) {
        double v = 0;
        if (!p.list) {
          if (!in.value(*p.value, v, error)) return false;
          if (p.role == Role::x || p.role == Role::y || p.role == Role::z) {
            const int d = p.role == Role::x ? 0 : p.role == Role::y ? 1 : 2;
            points[static_cast<size_t>(i)][d] = v;
          }
          continue;
        }
        double n = 0;
        if (!in.value(*p.count, n, error)) return false;
        if (n < 0) {
          error = in.where() + ": negative list length " + std::to_string(static_cast<long long>(n));
          return false;
        }
        const auto len = static_cast<std::uint64_t>(n);
        if (!ascii && len > in.remaining() / static_cast<std::uint64_t>(p.value->bytes)) {
          error = in.where() + ": a list of " + std::to_string(len) + " values runs past the end of the file (" +
                  std::to_string(in.remaining()) + " bytes left, truncated)";
          return false;
        }
        if (p.role == Role::face_indices) {
          if (len < 3) {
            error = in.where() + ": a face with " + std::to_string(len) + " corners (at least three needed)";
            return false;
          }
          corners.clear();
        }
        for (std::uint64_t k = 0; k < len; ++k) {
          if (!in.value(*p.value, v, error)) return false;
          if (p.role != Role::face_indices) continue;
          if (v < 0 || v >= vertex_count) {
            error = in.where() + ": vertex index " + std::to_string(static_cast<long long>(v)) +
                    " is out of range (the file has " + std::to_string(vertex->count) + " vertices)";
            return false;
          }
          corners.push_back(static_cast<int>(v));
        }
        if (p.role == Role::face_indices)
          for (size_t k = 1; k + 1 < corners.size(); ++k) tris.push_back({corners[0], corners[k], corners[k + 1]});
      }
      if (&e == vertex && !points[static_cast<size_t>(i)].allFinite()) {
        const vdm::Vec3& x = points[static_cast<size_t>(i)];
        std::ostringstream s;
        s << in.where() << ": non-finite coordinate (" << x.x() << ", " << x.y() << ", " << x.z() << ")";
        error = s.str();
        return false;
      }
      if (!in.end_item(error)) return false;
    }
  }
  if (!in.finish(error)) return false;

  mesh.positions.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) mesh.positions.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  mesh.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t k = 0; k < tris.size(); ++k)
    for (int c = 0; c < 3; ++c) mesh.triangles(static_cast<Eigen::Index>(k), c) = tris[k][static_cast<size_t>(c)];
  return true;
}

bool read_ply(const std::string& path, vdm::SurfaceMesh& mesh, std::string& error) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    error = "cannot open the file";
    return false;
  }
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (f.bad()) {
    error = "read error";
    return false;
  }
  return parse_ply(bytes, mesh, error);
}

}  // namespace vdmsim
