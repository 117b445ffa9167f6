// Mesh files (core/object/mesh_file_check.cc, mesh_repair.cc): the first byte picks the
// format, the rest is the file; what reads is validated, small meshes are also closed.
#include "core/object/mesh_repair.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kExt[4] = {".obj", ".off", ".ply", ".stl"};
  const std::string path = bimart::fuzz::input_file(data + 1, size - 1, kExt[data[0] % 4]);
  bimart::fuzz::only_bimart_errors([&] {
    bimart::TriangleMesh m = bimart::read_mesh_file(path);
    bimart::validate_mesh(m, path);
    if (m.num_faces() <= 64) bimart::close_and_orient(m, path);
  });
  return 0;
}
