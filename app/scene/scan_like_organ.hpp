#pragma once
// A liver surface as a CT segmentation gives it, made from the project's own liver so that
// tests and the tutorial need no patient data: millimetres, scanner coordinates, the surface
// bumpy (marching-cubes-like jitter), cropped where the scan ended (an open flat cut), a few
// small holes and duplicate triangles, and a fold of the left lobe pushed through its own
// underside (the surface passes through itself). `vdmsim prepare-mesh` turns it back into an
// organ.
#include "engine/types.hpp"

namespace vdmsim {

struct ScanLikeOptions {
  int level = 5;                 // of the liver it starts from (10242 nodes)
  double jitter_mm = 0.6;        // largest displacement along the normal
  double crop_mm = 18;           // the right lobe's end cut off, this far in from its tip
  bool fold = true;              // the pushed-through fold
  unsigned seed = 29;
  vdm::Vec3 scanner_offset_mm = vdm::Vec3(-92.5, 163.0, -1241.0);  // where the scanner's origin puts the organ
};

// The damaged surface in millimetres (a triangle soup: open, self-intersecting).
vdm::SurfaceMesh make_scan_like_liver(const ScanLikeOptions& options = {});

}  // namespace vdmsim
