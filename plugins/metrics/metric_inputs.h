// What the metric.* plug-ins share: the common input ports and one-sequence evaluation
// through core/metrics (the same code `bimart eval` runs). In a pipeline a metric sees one
// sequence, so its MetricResult covers that sequence (num_sequences = 1; Mul: one trajectory).
#pragma once

#include <ATen/ATen.h>

#include "core/hand/hand_motion.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"
#include "stages/metric.h"

namespace bimart {

inline StageSpec& declare_hand_object_inputs(StageSpec& s) {
  return s
      .input<HandMotion>("hand_params",
                         "both hands, world frame; `vertices` used when present, else posed with "
                         "models/hand/mano_{left,right}.npz")
      .input<ArticulatedObject>("object", "the two-part object, canonical frame, metres")
      .input<at::Tensor>("object_states", "[N, 7] float32: [angle, rx, ry, rz, tx, ty, tz]");
}

// Counts and means for the sequence on the stage's inputs.
inline SequenceMetrics evaluate_inputs(StageIO& io, bool with_contact_map = false) {
  const HandMotion& motion = io.in<HandMotion>("hand_params");
  const ArticulatedObject& object = io.in<ArticulatedObject>("object");
  SequenceData d;
  d.name = object.name;
  d.object_states = io.in<at::Tensor>("object_states");
  d.hand_vertices = hand_vertices(motion);
  if (with_contact_map) {
    d.hand_keypoints = hand_keypoints(motion);
    d.contact_maps = io.in<at::Tensor>("contact_maps");
    d.basis_hit_indices = io.in<at::Tensor>("basis_hit_indices");
  }
  const ObjectDistance distance(object);
  return evaluate_sequence(object, distance, d);
}

}  // namespace bimart
