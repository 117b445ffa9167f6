// PLY meshes (ascii, binary little and big endian): vertices (x, y, z) and polygonal faces
// (the list property `vertex_indices` or `vertex_index`), every other element and property
// read past. Hand-written instead of CGAL's PLY reader, which crashed on fuzzed files that
// passed a header check (tests/fuzz, docs/reliability.md): this one bounds every count by
// the bytes left in the file and names the line (ascii) or byte offset (binary) of a fault.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace bimart {

struct PlyMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::vector<std::int64_t>> faces;  // each with at least 3 corners in [0, vertices)
};

// Throws bimart::Error "path:line: what is wrong" (ascii, header) or "path: byte N: ..."
// (binary body) for a malformed file, a coordinate that is not finite, a face index out of
// range, no vertices or no faces.
PlyMesh read_ply_file(const std::string& path);

}  // namespace bimart
