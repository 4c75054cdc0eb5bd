#include "render/colormap.hpp"

#include <algorithm>
#include <cmath>

namespace render {
namespace {

struct Lab {
  double l, a, b;
};

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double linear_to_srgb(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
}

// sRGB (D65) <-> CIELAB.
constexpr double Xn = 0.95047, Yn = 1.0, Zn = 1.08883;
double f_lab(double t) { return t > 216.0 / 24389 ? std::cbrt(t) : (24389.0 / 27 * t + 16) / 116; }
double f_lab_inv(double t) { return t * t * t > 216.0 / 24389 ? t * t * t : (116 * t - 16) / (24389.0 / 27); }

Lab hex_to_lab(unsigned hex) {
  const double r = srgb_to_linear(((hex >> 16) & 0xff) / 255.0);
  const double g = srgb_to_linear(((hex >> 8) & 0xff) / 255.0);
  const double b = srgb_to_linear((hex & 0xff) / 255.0);
  const double X = 0.4124 * r + 0.3576 * g + 0.1805 * b;
  const double Y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
  const double Z = 0.0193 * r + 0.1192 * g + 0.9505 * b;
  const double fx = f_lab(X / Xn), fy = f_lab(Y / Yn), fz = f_lab(Z / Zn);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

Rgb8 lab_to_rgb8(const Lab& c) {
  const double fy = (c.l + 16) / 116, fx = fy + c.a / 500, fz = fy - c.b / 200;
  const double X = Xn * f_lab_inv(fx), Y = Yn * f_lab_inv(fy), Z = Zn * f_lab_inv(fz);
  const double r = 3.2406 * X - 1.5372 * Y - 0.4986 * Z;
  const double g = -0.9689 * X + 1.8758 * Y + 0.0415 * Z;
  const double b = 0.0557 * X - 0.2040 * Y + 1.0570 * Z;
  auto to8 = [](double v) { return static_cast<std::uint8_t>(std::lround(linear_to_srgb(v) * 255)); };
  return {to8(r), to8(g), to8(b)};
}

// Anchor colours, evenly spaced from t = 0 to 1 (published values of each map).
const std::vector<unsigned>& anchors(ColorMapName name) {
  static const std::vector<unsigned> viridis = {0x440154, 0x482475, 0x414487, 0x355F8D, 0x2A788E, 0x21918C,
                                                0x22A884, 0x44BF70, 0x7AD151, 0xBDDF26, 0xFDE725};
  static const std::vector<unsigned> magma = {0x000004, 0x140E36, 0x3B0F70, 0x641A80, 0x8C2981, 0xB73779,
                                              0xDE4968, 0xF7705C, 0xFE9F6D, 0xFECF92, 0xFCFDBF};
  static const std::vector<unsigned> inferno = {0x000004, 0x160B39, 0x420A68, 0x6A176E, 0x932667, 0xBC3754,
                                                0xDD513A, 0xF37819, 0xFCA50A, 0xF6D746, 0xFCFFA4};
  static const std::vector<unsigned> plasma = {0x0D0887, 0x41049D, 0x6A00A8, 0x8F0DA4, 0xB12A90, 0xCC4778,
                                               0xE16462, 0xF2844B, 0xFCA636, 0xFCCE25, 0xF0F921};
  static const std::vector<unsigned> coolwarm = {0x3B4CC0, 0xDDDDDD, 0xB40426};
  static const std::vector<unsigned> grey = {0x000000, 0xFFFFFF};
  switch (name) {
    case ColorMapName::viridis: return viridis;
    case ColorMapName::magma: return magma;
    case ColorMapName::inferno: return inferno;
    case ColorMapName::plasma: return plasma;
    case ColorMapName::coolwarm: return coolwarm;
    case ColorMapName::grey: return grey;
  }
  return viridis;
}

std::array<Rgb8, 256> tabulate(ColorMapName name) {
  const std::vector<unsigned>& hex = anchors(name);
  std::vector<Lab> lab;
  for (unsigned h : hex) lab.push_back(hex_to_lab(h));
  std::array<Rgb8, 256> table{};
  const int segments = static_cast<int>(lab.size()) - 1;
  for (int i = 0; i < 256; ++i) {
    const double t = i / 255.0 * segments;
    const int k = std::min(static_cast<int>(t), segments - 1);
    const double w = t - k;
    const Lab c{(1 - w) * lab[k].l + w * lab[k + 1].l, (1 - w) * lab[k].a + w * lab[k + 1].a,
                (1 - w) * lab[k].b + w * lab[k + 1].b};
    table[i] = lab_to_rgb8(c);
  }
  return table;
}

const ColorMapName kAll[] = {ColorMapName::viridis, ColorMapName::magma,    ColorMapName::inferno,
                             ColorMapName::plasma,  ColorMapName::coolwarm, ColorMapName::grey};

}  // namespace

const char* to_string(ColorMapName name) {
  switch (name) {
    case ColorMapName::viridis: return "viridis";
    case ColorMapName::magma: return "magma";
    case ColorMapName::inferno: return "inferno";
    case ColorMapName::plasma: return "plasma";
    case ColorMapName::coolwarm: return "coolwarm";
    case ColorMapName::grey: return "grey";
  }
  return "?";
}

std::vector<std::string> colormap_names() {
  std::vector<std::string> out;
  for (ColorMapName n : kAll) out.push_back(to_string(n));
  return out;
}

bool parse_colormap(const std::string& text, ColorMapName& out) {
  for (ColorMapName n : kAll)
    if (text == to_string(n)) {
      out = n;
      return true;
    }
  return false;
}

const std::array<Rgb8, 256>& colormap_table(ColorMapName name) {
  static const std::array<std::array<Rgb8, 256>, 6> tables = {tabulate(kAll[0]), tabulate(kAll[1]), tabulate(kAll[2]),
                                                              tabulate(kAll[3]), tabulate(kAll[4]), tabulate(kAll[5])};
  return tables[static_cast<int>(name)];
}

Rgb8 colormap(ColorMapName name, double t) {
  if (!(t >= 0)) t = 0;  // also NaN
  if (t > 1) t = 1;
  return colormap_table(name)[static_cast<int>(std::lround(t * 255))];
}

}  // namespace render
