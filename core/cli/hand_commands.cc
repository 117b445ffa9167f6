// bimart hand make: generate the procedural MANO-layout hand files (and a picture of them).
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <vector>

#include "core/cli/command.h"
#include "core/hand/lbs.h"
#include "core/hand/procedural_hand.h"
#include "core/render/rasterizer.h"
#include "core/util/error.h"
#include "core/util/output_path.h"

namespace bimart::cli {

namespace {

TriangleMesh posed_mesh(const HandModel& m, const Eigen::VectorXd& pose) {
  const Eigen::Vector3d zero3 = Eigen::Vector3d::Zero();
  const LbsResult<double> r = lbs<double>(m, zero3, pose, zero3, Eigen::VectorXd::Zero(HandModel::kNumBetas));
  return TriangleMesh{r.vertices, m.faces};
}

// Palm-side view, fingers up: rest pose, then a loose fist (same camera for both).
std::vector<Image> pictures(const HandModel& m, int size) {
  const TriangleMesh rest{m.v_template, m.faces};
  const TriangleMesh fist = posed_mesh(m, procedural_curl_pose(m.side, 0.9, 0.8));
  const Eigen::Vector3d skin(0.87, 0.68, 0.58);
  const double mirror = m.side == HandSide::Left ? -1 : 1;
  const Eigen::Vector3d view(-0.25 * mirror, 1.0, -0.35);  // from the palm side, a little from the wrist
  std::vector<Image> out;
  for (const TriangleMesh* mesh : {&rest, &fist}) {
    Camera cam = frame_items({{&rest, skin}}, view);
    cam.up = Eigen::Vector3d(-mirror, 0, 0);  // fingers point along -x (right) / +x (left)
    out.push_back(render({{mesh, skin}}, cam, size, size));
  }
  return out;
}

int make(const std::string& which, const std::string& out_dir, const std::string& picture) {
  std::vector<HandSide> sides;
  if (which == "right" || which == "both") sides.push_back(HandSide::Right);
  if (which == "left" || which == "both") sides.push_back(HandSide::Left);
  // Every output is checked, and the picture drawn, before the first file is written.
  std::vector<std::string> paths;
  for (HandSide side : sides)
    paths.push_back(
        (std::filesystem::path(out_dir) / (side == HandSide::Right ? "mano_right.npz" : "mano_left.npz")).string());
  for (const std::string& p : paths) check_output_file(p);
  if (!picture.empty()) check_output_file(picture);
  std::vector<HandModel> models;
  std::vector<Image> images;
  for (HandSide side : sides) {
    models.push_back(make_procedural_hand(side));
    if (!picture.empty())
      for (Image& im : pictures(models.back(), 420)) images.push_back(std::move(im));
  }
  if (!picture.empty()) tile(images, 2).save_png(picture);
  for (size_t i = 0; i < models.size(); ++i) {
    save_hand_model(models[i], paths[i]);
    std::cout << fmt::format("wrote {} ({} vertices, {} faces)\n", paths[i], models[i].num_vertices(),
                             models[i].num_faces());
  }
  if (!picture.empty()) std::cout << "wrote " << picture << "\n";
  return 0;
}

}  // namespace

void add_hand_commands(CLI::App& app, Commands& out) {
  CLI::App* hand = app.add_subcommand("hand", "hand models");
  hand->require_subcommand(1);
  static std::string side = "both", dir, picture;
  CLI::App* make_cmd = hand->add_subcommand("make", "write the procedural MANO-layout hand (mano_right/left.npz)");
  make_cmd->add_option("--side", side, "right, left or both")->check(CLI::IsMember({"right", "left", "both"}));
  make_cmd->add_option("--out", dir, "output folder")->required();
  make_cmd->add_option("--picture", picture, "also write a PNG: rest pose and a loose fist per hand");
  out.push_back({make_cmd, [] { return make(side, dir, picture); }, false});
}

}  // namespace bimart::cli
