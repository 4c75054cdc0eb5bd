#include "app/run/vtk_xml.hpp"

#include <charconv>

namespace vdmsim {
namespace {

// Appends `v` in its shortest form that reads back to the same value ("0.1", "-2.5e-07").
template <typename T>
void append_number(std::string& out, T v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// Characters a name may not hold in an XML attribute.
std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

// An N x 3 array (points, or triangles' node indices), one row per line.
template <typename Matrix>
void append_rows(std::string& out, const Matrix& m) {
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    out += "          ";
    for (int d = 0; d < 3; ++d) {
      if (d) out += ' ';
      append_number(out, m(i, d));
    }
    out += '\n';
  }
}

void open_array(std::string& out, const char* type, const std::string& name, int components) {
  out += "        <DataArray type=\"";
  out += type;
  out += '"';
  if (!name.empty()) out += " Name=\"" + xml_escape(name) + '"';
  if (components > 1) out += " NumberOfComponents=\"" + std::to_string(components) + '"';
  out += " format=\"ascii\">\n";
}

const char* const kCloseArray = "        </DataArray>\n";

}  // namespace

std::string vtu_text(const vdm::NodeMat& points, const vdm::TriMat& triangles, const std::vector<VtuVectors>& vectors,
                     const std::vector<VtuScalars>& scalars) {
  std::string out;
  out.reserve(static_cast<size_t>(points.rows()) * (64 + 48 * vectors.size() + 16 * scalars.size()) +
              static_cast<size_t>(triangles.rows()) * 32 + 1024);
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
         "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" +
         std::to_string(points.rows()) + "\" NumberOfCells=\"" + std::to_string(triangles.rows()) + "\">\n";
  // The first vector array is the one ParaView takes as the points' vectors (e.g. for glyphs).
  out += "      <PointData";
  if (!vectors.empty()) out += " Vectors=\"" + xml_escape(vectors.front().name) + '"';
  out += ">\n";
  for (const VtuVectors& v : vectors) {
    open_array(out, "Float64", v.name, 3);
    append_rows(out, *v.values);
    out += kCloseArray;
  }
  for (const VtuScalars& s : scalars) {
    open_array(out, "Float32", s.name, 1);
    for (float x : *s.values) {
      out += "          ";
      append_number(out, x);
      out += '\n';
    }
    out += kCloseArray;
  }
  out += "      </PointData>\n      <Points>\n";
  open_array(out, "Float64", "", 3);
  append_rows(out, points);
  out += kCloseArray;
  out += "      </Points>\n      <Cells>\n";
  open_array(out, "Int64", "connectivity", 1);
  append_rows(out, triangles);
  out += kCloseArray;
  // Where each cell's nodes end in `connectivity`, and the cells' type: VTK_TRIANGLE = 5.
  open_array(out, "Int64", "offsets", 1);
  for (Eigen::Index t = 1; t <= triangles.rows(); ++t) {
    out += "          ";
    append_number(out, 3 * t);
    out += '\n';
  }
  out += kCloseArray;
  open_array(out, "UInt8", "types", 1);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) out += "          5\n";
  out += kCloseArray;
  out += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return out;
}

std::string pvd_text(const std::vector<PvdDataSet>& datasets) {
  std::string out =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const PvdDataSet& d : datasets) {
    out += "    <DataSet timestep=\"";
    append_number(out, d.time);
    out += "\" group=\"\" part=\"0\" file=\"" + xml_escape(d.file) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  return out;
}

}  // namespace vdmsim
