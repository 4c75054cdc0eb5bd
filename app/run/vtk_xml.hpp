#pragma once
// VTK's XML file formats as plain text, without VTK: an UnstructuredGrid (.vtu) of a triangle
// surface with point data, and a Collection (.pvd), the time series ParaView opens. "ascii"
// DataArrays and shortest round-trip numbers (std::to_chars), so that the files are readable,
// read back bit for bit, and the same input gives the same bytes.
#include <string>
#include <vector>

#include "engine/types.hpp"

namespace vdmsim {

// A 3-component point array (N x 3), written as Float64.
struct VtuVectors {
  std::string name;
  const vdm::NodeMat* values = nullptr;
};

// A scalar point array (N values), written as Float32: the precision it is computed in.
struct VtuScalars {
  std::string name;
  const std::vector<float>* values = nullptr;
};

// The surface `triangles` at `points` (N x 3, m) as a .vtu file's text: VTK_TRIANGLE cells
// (type 5), the vectors then the scalars as point data, in the order given.
std::string vtu_text(const vdm::NodeMat& points, const vdm::TriMat& triangles, const std::vector<VtuVectors>& vectors,
                     const std::vector<VtuScalars>& scalars);

// One entry of a .pvd collection: a file (relative to the .pvd) and its time (s).
struct PvdDataSet {
  double time = 0;
  std::string file;
};

// A .pvd file's text listing `datasets` in the order given.
std::string pvd_text(const std::vector<PvdDataSet>& datasets);

}  // namespace vdmsim
