// The inputs export.gltf and export.html share: the refined hands, the object and its
// trajectory, optional contact maps, every sample (stages/samples.h), and the hand models
// that pose the hands.
#pragma once

#include <memory>
#include <string>

#include <ATen/core/Tensor.h>

#include "core/export/scene_source.h"
#include "core/pipeline/plugin.h"
#include "stages/samples.h"

namespace bimart::outputs_plugin {

inline void declare_scene_inputs(StageSpec& s) {
  s.input<HandMotion>("hand_params", "the hands, world frame")
      .input<ArticulatedObject>("object", "the object, canonical frame")
      .input<at::Tensor>("object_states", "[N, 7] object states")
      .input<double>("fps", "frames per second")
      .optional_input<std::string>("object_path", "the object's folder or YAML (informative)")
      .optional_input<at::Tensor>("contact_maps", "[N, 2, 1024] contact maps that conditioned the motion (m)")
      .optional_input<at::Tensor>("basis_hit_indices", "[N, 1024] int64, with contact_maps")
      .param("mano_left", "", "left hand model .npz (empty: the shipped hand; give both or neither)")
      .param("mano_right", "", "right hand model .npz (the models the hands were made with)")
      .param("name", "", "sequence name shown in the file (default: the file's stem)");
  declare_sample_ports(s);
}

// The scene of one sample (stage_samples(io)).
inline SceneSource scene_from_inputs(StageIO& io, const std::shared_ptr<const std::array<HandModel, 2>>& hands,
                                     const std::string& name, const StageSample& sample) {
  SceneSource src;
  src.sequence.name = name;
  src.sequence.object = io.has("object_path") ? io.in<std::string>("object_path") : "(from the pipeline)";
  src.sequence.fps = io.in<double>("fps");
  src.sequence.object_states = io.in<at::Tensor>("object_states");
  src.sequence.hands = *sample.hands;
  if (sample.contact_maps.defined() && io.has("basis_hit_indices")) {
    src.sequence.contact_maps = sample.contact_maps.contiguous();
    src.sequence.basis_hit_indices = io.in<at::Tensor>("basis_hit_indices");
  }
  src.object = io.in<ArticulatedObject>("object");
  src.hands = hands;
  src.sequence.validate();
  check_hands_fit(src.sequence, src.models(), "stage '" + io.stage_id() + "'");
  return src;
}

}  // namespace bimart::outputs_plugin
