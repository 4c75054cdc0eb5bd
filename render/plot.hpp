#pragma once
// Line plots as PNG, drawn by the project with ImGui draw lists in an offscreen context:
// one or more panels in a grid, each with axes, ticks, grid, labels with units, a legend, and
// optional log scales. Used by `vdmsim paper`, the accuracy study and the benchmarks.
#include <string>
#include <vector>

namespace render {

struct Series {
  std::string label;
  std::vector<double> x, y;
  int color = -1;          // index in the palette (colour-blind safe); -1: by position
  bool line = true;        // connect the points
  bool markers = false;    // a dot at each point
  bool dashed = false;
};

struct Panel {
  std::string title, x_label, y_label;  // labels carry units, e.g. "time (s)"
  bool log_x = false, log_y = false;    // non-positive values are left out on a log axis
  std::vector<Series> series;
};

struct Figure {
  std::string title;
  int columns = 1;
  int panel_width = 640, panel_height = 420;  // pixels per panel
  std::vector<Panel> panels;
};

bool write_figure_png(const Figure& figure, const std::string& path, std::string& error);

}  // namespace render
