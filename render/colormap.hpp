#pragma once
// Colour maps for the stress view and plots. The sequential maps (viridis by default, magma,
// inferno, plasma) are perceptually uniform; `coolwarm` is a diverging map for signed
// quantities (stress components, volumetric strain). Each map is a set of anchor colours
// interpolated in CIELAB, tabulated at 256 entries.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace render {

enum class ColorMapName { viridis, magma, inferno, plasma, coolwarm, grey };

struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
};

// Parses a map name; false when unknown.
bool parse_colormap(const std::string& text, ColorMapName& out);
const char* to_string(ColorMapName name);
std::vector<std::string> colormap_names();

// 256 entries from t = 0 to t = 1.
const std::array<Rgb8, 256>& colormap_table(ColorMapName name);
// The colour at t (clamped to [0, 1]).
Rgb8 colormap(ColorMapName name, double t);

}  // namespace render
