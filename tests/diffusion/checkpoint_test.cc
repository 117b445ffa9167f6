// Checkpoints: round trip, compatibility errors naming what differs, truncated and foreign
// files refused with a message.
#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/diffusion/checkpoint.h"
#include "core/io/npz.h"
#include "core/util/error.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart::diffusion {
namespace {

namespace fs = std::filesystem;

NormalizationStats unit_stats() {
  NormalizationStats s;
  s.variant = "np_bps";
  s.count = 10;
  s.x_mean = at::zeros({1200}, at::kDouble);
  s.x_std = at::ones({1200}, at::kDouble);
  s.obj_mean = at::zeros({3079}, at::kDouble);
  s.obj_std = at::ones({3079}, at::kDouble);
  s.c_mean = at::zeros({2048}, at::kDouble);
  s.c_std = at::ones({2048}, at::kDouble);
  return s;
}

Checkpoint tiny_checkpoint(const std::string& output = "x0") {
  Checkpoint c;
  c.info.network = DenoiserConfig::paper("contact");
  c.info.network.output = output;
  c.info.network.latent = 16;
  c.info.network.layers = 1;
  c.info.network.heads = 2;
  c.info.network.feedforward = 16;
  c.info.network.condition_hidden = 8;
  c.info.basis_points = at::rand({1024, 3});
  for (int i = 0; i < 100; ++i) c.info.keypoints.push_back(7 * i);
  c.info.normalization = unit_stats();
  c.info.config_text = "model: contact\n";
  c.info.data_fingerprint = "0123456789abcdef";
  torch::manual_seed(3);
  Denoiser net(c.info.network);
  c.weights = state_of(*net);
  return c;
}

std::string scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_ckpt_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

TEST(Checkpoint, RoundTripKeepsWeightsAndInfo) {
  const Checkpoint c = tiny_checkpoint();
  const std::string path = scratch("round.npz");
  save_checkpoint(c, path);
  const Checkpoint r = load_checkpoint(path);
  EXPECT_EQ(r.info.network.describe(), c.info.network.describe());
  EXPECT_EQ(r.info.keypoints, c.info.keypoints);
  EXPECT_TRUE(at::equal(r.info.basis_points, c.info.basis_points));
  EXPECT_EQ(r.info.data_fingerprint, c.info.data_fingerprint);
  EXPECT_EQ(r.info.config_text, c.info.config_text);
  ASSERT_EQ(r.weights.size(), c.weights.size());
  for (const auto& [k, v] : c.weights) EXPECT_TRUE(at::equal(r.weights.at(k), v)) << k;
  EXPECT_FALSE(r.train.has_value());
  const Denoiser net = make_denoiser(r, path);
  for (const auto& p : net->named_parameters()) EXPECT_TRUE(at::equal(p.value(), c.weights.at(p.key())));
}

TEST(Checkpoint, HalfPrecisionWeightsLoadAsTheirFloat32Values) {
  // An export with export_half stores parameters as float16: about half the file, and on
  // load the network gets exactly the rounded values, in float32.
  Checkpoint c = tiny_checkpoint();
  const std::string full = scratch("full.npz"), half = scratch("half.npz");
  save_checkpoint(c, full);
  for (auto& [k, v] : c.weights)
    if (v.scalar_type() == at::kFloat) v = v.to(at::kHalf);
  save_checkpoint(c, half);
  const Checkpoint r = load_checkpoint(half);
  const Denoiser net = make_denoiser(r, half);
  for (const auto& p : net->named_parameters()) {
    EXPECT_EQ(p.value().scalar_type(), at::kFloat);
    EXPECT_TRUE(at::equal(p.value(), c.weights.at(p.key()).to(at::kFloat))) << p.key();
  }
  const double weights_bytes = 4.0 * static_cast<double>(net->num_parameters());
  EXPECT_NEAR(static_cast<double>(fs::file_size(full) - fs::file_size(half)), weights_bytes / 2, weights_bytes * 0.02);
}

TEST(Checkpoint, OutputKindRoundTripsAndOlderFilesPredictX0) {
  Checkpoint c = tiny_checkpoint("gaussian");
  ASSERT_EQ(c.weights.count("skip_directions"), 1u);
  const std::string path = scratch("gaussian.npz");
  save_checkpoint(c, path);
  EXPECT_EQ(load_checkpoint(path).info.network.output, "gaussian");
  // A checkpoint written before the output kind existed has no network/output: it was x0.
  const NpzFile f = NpzFile::read(path);
  NpzFile older;
  for (const auto& key : f.keys())
    if (key != "network/output" && key != "network/skip_rank" && key.find("skip_") == std::string::npos)
      older.set(key, f.get(key));
  const std::string old_path = scratch("older.npz");
  older.write(old_path, NpzCompression::Store);
  EXPECT_EQ(load_checkpoint(old_path).info.network.output, "x0");
}

TEST(Checkpoint, ContactCueRoundTripsWithItsFrame) {
  Checkpoint c = tiny_checkpoint();
  c.info.network = DenoiserConfig::paper("motion");
  c.info.network.latent = 16;
  c.info.network.layers = 1;
  c.info.network.heads = 2;
  c.info.network.feedforward = 16;
  c.info.network.condition_hidden = 8;
  c.info.network.contact_cue = true;
  c.info.network.contact_points = 16;
  c.info.network.point_hidden = 8;
  Denoiser net(c.info.network);
  net->set_cue_frame(at::zeros({3079}), at::full({3079}, 2.0), at::zeros({2048}), at::ones({2048}), c.info.basis_points,
                     false);
  c.weights = state_of(*net);
  const std::string path = scratch("cue.npz");
  save_checkpoint(c, path);
  const Checkpoint r = load_checkpoint(path);
  EXPECT_TRUE(r.info.network.contact_cue);
  EXPECT_EQ(r.info.network.contact_points, 16);
  EXPECT_EQ(r.info.network.point_hidden, 8);
  const Denoiser back = make_denoiser(r, path);
  EXPECT_TRUE(at::equal(back->named_buffers()["cue_basis"], c.info.basis_points));
  EXPECT_EQ(back->named_buffers()["cue_scaled"].item<float>(), 0.0f);
  save_checkpoint(tiny_checkpoint(), scratch("plain.npz"));
  EXPECT_FALSE(load_checkpoint(scratch("plain.npz")).info.network.contact_cue);
  EXPECT_EQ(load_checkpoint(scratch("plain.npz")).info.network.contact_points, 0);
}

TEST(Checkpoint, MismatchesNameWhatDiffers) {
  const Checkpoint c = tiny_checkpoint();
  EXPECT_NO_THROW(check_compatible(c.info, "m.npz", "contact", "np_bps", c.info.basis_points, c.info.keypoints));
  const std::string kind = error_of([&] { check_compatible(c.info, "m.npz", "motion", "", {}, {}); });
  EXPECT_NE(kind.find("not a motion model"), std::string::npos) << kind;
  const std::string variant = error_of([&] { check_compatible(c.info, "m.npz", "", "u_bps", {}, {}); });
  EXPECT_NE(variant.find("encoder variant"), std::string::npos) << variant;
  const std::string basis =
      error_of([&] { check_compatible(c.info, "m.npz", "", "", c.info.basis_points + 0.01, {}); });
  EXPECT_NE(basis.find("basis points"), std::string::npos) << basis;
  auto other = c.info.keypoints;
  other[5] += 1;
  const std::string keys = error_of([&] { check_compatible(c.info, "m.npz", "", "", {}, other); });
  EXPECT_NE(keys.find("hand keypoints"), std::string::npos) << keys;
  EXPECT_NE(keys.find("index 5"), std::string::npos) << keys;
  // Weights of another network.
  DenoiserConfig bigger = c.info.network;
  bigger.latent = 32;
  Denoiser net(bigger);
  const std::string shape = error_of([&] { load_state(*net, c.weights, "m.npz"); });
  EXPECT_NE(shape.find("m.npz"), std::string::npos) << shape;
  EXPECT_NE(shape.find("shape"), std::string::npos) << shape;
}

TEST(Checkpoint, TruncatedAndForeignFilesAreClearErrors) {
  const std::string path = scratch("whole.npz");
  save_checkpoint(tiny_checkpoint(), path);
  const auto size = fs::file_size(path);
  for (const double keep : {0.0, 0.1, 0.5, 0.99}) {
    const std::string cut = scratch("cut.npz");
    fs::copy_file(path, cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, static_cast<std::uintmax_t>(keep * size));
    const std::string msg = error_of([&] { load_checkpoint(cut); });
    EXPECT_NE(msg.find(cut), std::string::npos) << keep << ": " << msg;
  }
  NpzFile foreign;
  foreign.set("x", make_npy_scalar<double>(1.0));
  const std::string other = scratch("foreign.npz");
  foreign.write(other);
  const std::string msg = error_of([&] { load_checkpoint(other); });
  EXPECT_NE(msg.find("not a bimart model checkpoint"), std::string::npos) << msg;
}

}  // namespace
}  // namespace bimart::diffusion
