// A tiny data set built in a scratch folder once per test process: one procedural box,
// four short sequences (hands posed from parameters, no stored vertices) and a manifest.
//   train: sequences/use_a.npz   (100 frames, the hinge opens, the object moves)
//          sequences/grab_b.npz  (64 frames, hinge fixed: one O row for all frames)
//          sequences/short_c.npz (40 frames: one padded window)
//   test:  sequences/test_d.npz  (80 frames)
// Root translation is analytic: t(f) = (0.3 + 0.01 f, 0.1 - 0.02 f, -0.2 + 0.005 f).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <ATen/ATen.h>

#include "core/data/manifest.h"
#include "core/data/window_dataset.h"
#include "core/io/sequence.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"

namespace bimart::testing_data {

namespace fs = std::filesystem;

inline double translation(int axis, int64_t f) {
  const double base[3] = {0.3, 0.1, -0.2}, slope[3] = {0.01, -0.02, 0.005};
  return base[axis] + slope[axis] * static_cast<double>(f);
}

// `open`: whether the hinge angle changes from frame to frame.
inline Sequence make_sequence(const std::string& name, int64_t n, bool open, uint64_t seed) {
  at::manual_seed(seed);
  Sequence s;
  s.name = name;
  s.object = "../objects/box";
  s.category = "box";
  s.kind = open ? "use" : "grab";
  s.fps = 30;
  s.object_states = at::zeros({n, 7}, at::kFloat);
  for (int64_t f = 0; f < n; ++f) {
    s.object_states[f][0] = open ? 0.1 + 0.012 * f : 0.4;
    s.object_states[f][1] = 0.2 + 0.004 * f;
    s.object_states[f][2] = -0.1;
    s.object_states[f][3] = 0.05 * std::sin(0.1 * f);
    for (int c = 0; c < 3; ++c) s.object_states[f][4 + c] = translation(c, f);
  }
  for (int h = 0; h < 2; ++h) {
    HandParams& p = s.hands.hands[h];
    p.rot = at::randn({n, 3}) * 0.3;
    p.pose = at::randn({n, 45}) * 0.15;
    // Near the object: its translation plus a few centimetres, drifting smoothly.
    p.trans = s.object_states.narrow(1, 4, 3) + at::randn({1, 3}) * 0.05 + at::randn({n, 3}) * 0.005;
    p.shape = at::randn({10}) * 0.5;
  }
  return s;
}

struct TinyDataset {
  fs::path dir;
  DatasetManifest manifest;
};

inline const TinyDataset& tiny_dataset() {
  static const TinyDataset d = [] {
    TinyDataset t;
    t.dir = fs::temp_directory_path() / ("bimart_data_tests_" + std::to_string(::getpid()));
    fs::remove_all(t.dir);
    save_object(make_object("box", 3), (t.dir / "objects" / "box").string());
    write_sequence(make_sequence("use_a", 100, true, 1), (t.dir / "sequences" / "use_a.npz").string());
    write_sequence(make_sequence("grab_b", 64, false, 2), (t.dir / "sequences" / "grab_b.npz").string());
    write_sequence(make_sequence("short_c", 40, true, 3), (t.dir / "sequences" / "short_c.npz").string());
    write_sequence(make_sequence("test_d", 80, true, 4), (t.dir / "sequences" / "test_d.npz").string());
    t.manifest.generator = "bimart data tests";
    t.manifest.seed = 5;
    t.manifest.train = {"sequences/use_a.npz", "sequences/grab_b.npz", "sequences/short_c.npz"};
    t.manifest.test = {"sequences/test_d.npz"};
    t.manifest.objects = {{"box", "objects/box", "box", "train"}};
    write_manifest(t.manifest, t.dir.string());
    struct Remove {
      fs::path dir;
      ~Remove() {
        std::error_code ec;
        fs::remove_all(dir, ec);
      }
    };
    static const Remove remove_at_exit{t.dir};
    return t;
  }();
  return d;
}

// The train split, NP-BPS, float16, no disk cache: opened once per process.
inline const WindowDataset& tiny_train() {
  static const WindowDataset ds = [] {
    WindowDatasetOptions o;
    o.cache = false;
    return WindowDataset::open(tiny_dataset().dir.string(), "train", o);
  }();
  return ds;
}

}  // namespace bimart::testing_data
