// Shared set-up of the bad-input tests: a scratch folder with a box object and valid
// sequences that each test then spoils in one way.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <ATen/ATen.h>

#include "core/io/sequence.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"

namespace bimart::test {

namespace fs = std::filesystem;

// A fresh folder under the temp dir, removed at the end.
struct ScratchDir {
  fs::path path;
  explicit ScratchDir(const std::string& name)
      : path(fs::temp_directory_path() / ("bimart_robust_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() { fs::remove_all(path); }
  std::string operator/(const std::string& rel) const { return (path / rel).string(); }
};

// N frames of a closed box moving along x, both hands flat 30 cm above it (posed from the
// MANO parameters by the reader), object at ../objects/box.
inline Sequence hover_sequence(const std::string& name, int64_t n = 8) {
  Sequence s;
  s.name = name;
  s.object = "../objects/box";
  s.category = "box";
  s.kind = "grab";
  s.object_states = at::zeros({n, 7});
  s.object_states.select(1, 4).copy_(at::arange(n, at::kFloat) * 0.01);
  for (int h = 0; h < 2; ++h) {
    auto& p = s.hands.hands[static_cast<size_t>(h)];
    p.rot = at::zeros({n, 3});
    p.pose = at::zeros({n, 45});
    p.trans = at::zeros({n, 3});
    p.trans.select(1, 1).fill_(0.3);
    p.trans.select(1, 0).fill_(h == 0 ? -0.1 : 0.1);
    p.shape = at::zeros({10});
  }
  return s;
}

// DIR/objects/box and DIR/gen/ for sequences.
inline void write_box(const ScratchDir& dir) { save_object(make_object("box", 1), dir / "objects/box"); }

inline void write_text(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace bimart::test
