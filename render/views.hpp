#pragma once
// The views a run can draw of each frame, one row of a table each: its name in a scene's
// `render.views`, the folder and file its images go to, how it is drawn and how its image is
// stored. Everything that handles views (the scene reader and its reference, the frame
// output, videos, run.json, sweeps) goes through this table; the renderer draws each view
// (Renderer::draw_views).
#include <string>
#include <vector>

namespace render {

// In the order of the table.
enum class View { shaded, stress, depth, segmentation, normals };

// How a view's image is stored.
enum class ViewFile {
  png_rgb,      // 8-bit RGB PNG
  png_grey,     // 8-bit greyscale PNG
  npy_float32,  // NumPy .npy, little-endian float32, height x width
};

// How a view is drawn.
enum class ViewPass {
  picture,       // lit or colour-mapped, anti-aliased, with the HUD: for a person to look at
  ground_truth,  // the scene's objects only (organ, instruments: no floor, no background), one
                 // exact sample per pixel, no lighting, no HUD: for measuring
};

struct ViewRow {
  View view;
  const char* name;     // in render.views and run.json
  const char* folder;   // DIR/<folder>/
  const char* prefix;   // DIR/<folder>/<prefix>_NNNNN<extension>
  ViewFile file;
  ViewPass pass;
};

// Every view, in the order of View.
const std::vector<ViewRow>& view_table();
const ViewRow& view_row(View v);
// The view named `name` (a row's name); false when there is none.
bool parse_view(const std::string& name, View& out);
std::vector<std::string> view_names();  // in the table's order

const char* file_extension(ViewFile f);  // ".png", ".npy"
// The file of frame f of the view: <prefix>_NNNNN<extension>, e.g. depth_00012.npy.
std::string view_file_name(const ViewRow& row, int f);

// The video `run --video` makes of a picture view among `views` (a scene's, in the table's
// order): video.mp4 for the first picture view, <name>.mp4 for the others; empty for a
// ground-truth view.
std::string video_file_name(const std::vector<View>& views, View v);

// The segmentation view's ids: 0 the background, 1 the organ, 2 + i instruments[i]; with
// several organs 1 + i organs[i], then 1 + organs + k instruments[k].
constexpr int kOrganId = 1;
constexpr int kFirstInstrumentId = 2;
constexpr int kMaxInstrumentsWithIds = 255 - kFirstInstrumentId + 1;  // ids fit 8 bits (one organ)
constexpr int organ_id(int organ) { return kOrganId + organ; }
constexpr int instrument_id(int instrument, int organs) { return kFirstInstrumentId + (organs > 1 ? organs - 1 : 0) + instrument; }

}  // namespace render
