// A pass over a mesh file before CGAL reads it (PLY: our own reader, core/object/ply_file.h). CGAL's reader answers every fault with
// `false` (and allocates whatever a header declares), so this names the fault and its line
// — empty file, binary bytes in a text format, a coordinate that is no finite number, a face
// index out of range (OBJ counts from 1), no vertices or faces, a header declaring more
// elements than the file can hold — in one streaming pass that keeps no geometry.
// Hand-written because no Debian library reports these; it checks, CGAL still parses.
#pragma once

#include <string>

namespace bimart {

// OBJ, OFF, PLY (ascii and binary) and STL (ascii and binary), by extension. Throws
// bimart::Error "file:line: what is wrong"; returns quietly for a file CGAL may read.
void check_mesh_file(const std::string& path);

}  // namespace bimart
