#pragma once
// A direct PLY reader (ascii, binary little and big endian): vertex positions x, y, z and the
// face element's vertex index lists (polygons fanned into triangles). Every other property and
// element is skipped by its declared type. Keeps the file's vertex order and, for ascii, the
// digits written (double precision), like the OBJ reader.
//
// Strict: the element counts are checked against the bytes that follow the header before
// anything is allocated (a header claiming billions of vertices in a small file is refused),
// and truncated data, a value that does not fit its type, a face index out of range, a
// non-finite coordinate, a face with fewer than three corners, a missing end_header or an
// unknown format or type is an error. Errors name the line (header, ascii data) or the item
// and byte offset (binary data).
#include <string>
#include <string_view>

#include "engine/types.hpp"

namespace vdmsim {

// True when the bytes start like a PLY file: "ply" (in any case) and the end of the line.
bool looks_like_ply(std::string_view head);

// Parses PLY bytes into `mesh` (all vertices, in file order). On failure returns false and sets
// `error` to "line N: what is wrong" or "<element> K (byte offset B): what is wrong".
bool parse_ply(std::string_view bytes, vdm::SurfaceMesh& mesh, std::string& error);

// Reads the file at `path` and parses it (the caller bounds the file size and adds the file
// name to the error).
bool read_ply(const std::string& path, vdm::SurfaceMesh& mesh, std::string& error);

}  // namespace vdmsim
