#pragma once
// The bench's CT-like organ: SOFA's scanned liver (third-party, in the shared assets, never
// shipped) made an organ by prepare-mesh, and a probe press on it like probe_poke's.
#include <filesystem>
#include <string>

namespace vdmsim {

// Writes DIR/scanned_liver.obj (the shared assets' organs/liver-smooth.obj at 22 cm, 10k
// nodes, centred) and DIR/scanned_liver_press.yaml: a 4 mm probe comes down on the top of the
// organ at x = 2 cm, presses 1 cm into it over 0.8 s and holds; the organ rests on its lowest
// fifth. Returns the scene's path, or "" with `why_not` when the asset is not there or cannot be
// prepared.
std::string scanned_liver_press_scene(const std::filesystem::path& shared_assets, const std::filesystem::path& dir,
                                      std::string& why_not);

}  // namespace vdmsim
