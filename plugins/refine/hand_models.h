// The hand models a refine stage poses: its `mano_left` / `mano_right` parameters, or the
// shipped procedural hands when both are empty.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "core/hand/hand_model.h"
#include "core/pipeline/params.h"
#include "core/pipeline/stage.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart::refine_plugin {

inline void declare_hand_params(StageSpec& s) {
  s.param("mano_left", "", "left hand model .npz (empty: the shipped hand; give both or neither)")
      .param("mano_right", "", "right hand model .npz (e.g. converted MANO, tools/mano_to_npz.py)");
}

struct HandPair {
  std::array<HandModel, 2> models;
  std::array<const HandModel*, 2> pointers() const { return {&models[0], &models[1]}; }
};

inline std::shared_ptr<const HandPair> load_hand_pair(const Params& p) {
  const std::string& left = p.string("mano_left");
  const std::string& right = p.string("mano_right");
  if (left.empty() != right.empty()) throw Error("give both mano_left and mano_right, or neither");
  auto pair = std::make_shared<HandPair>();
  pair->models = load_hand_models(left.empty() ? find_data_file("models/hand/mano_left.npz") : left,
                                  right.empty() ? find_data_file("models/hand/mano_right.npz") : right);
  return pair;
}

}  // namespace bimart::refine_plugin
