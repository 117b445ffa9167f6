// All of DESIGN §6 for one sequence (the counts and means behind every measure), and the
// aggregation over sequences into the paper's table: frame counts summed over sequences
// for Pen/Con/Art, per-sequence means averaged for Accel and CM, per-trajectory pair
// means averaged for Mul. `bimart eval` and the metric.* plug-ins share these.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/metrics/frame_count.h"
#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"
#include "stages/metric.h"

namespace bimart {

struct SequenceMetrics {
  std::string name;
  std::int64_t frames = 0;
  double accel = std::numeric_limits<double>::quiet_NaN();  // m/frame²; NaN when N < 3
  FrameCount pen_1cm, pen_5mm, pen_3mm, contact, articulation;
  // The deepest penetration (m, 0 when outside) summed over the frames where a hand touches
  // the object (deepest vertex within kContactDistance of it, or inside), and their count:
  // the "Depth" column, a hand resting on the surface against one sunk into it.
  double contact_depth_sum = 0;
  std::int64_t contact_depth_frames = 0;
  // Frames with a hand bent outside its joints' ranges or fingers inside each other
  // (core/metrics/hand_plausibility.h): the "Implaus" column.
  FrameCount implausible;
  FrameCount cavity;  // frames with a hand in a part's cavity (core/metrics/penetration.h): "Cavity"
  std::string implausible_first;  // the first such frame and why ("frame 3, left hand: ...")
  double contact_map = std::numeric_limits<double>::quiet_NaN();  // m; NaN without a condition
};

// What evaluate_sequence needs beyond the object. Optional tensors may stay undefined.
struct SequenceData {
  std::string name;
  at::Tensor object_states;      // [N, 7]
  at::Tensor hand_vertices;      // [2, N, V, 3] world (core/metrics/hand_vertices.h)
  at::Tensor hand_keypoints;     // [2, N, J, 3], for CM only
  at::Tensor contact_maps;       // [N, 2, 1024] conditioning maps, for CM only
  at::Tensor basis_hit_indices;  // [N, 1024], for CM only
};

// `distance` must have been built from `object` (build it once per object).
SequenceMetrics evaluate_sequence(const ArticulatedObject& object, const ObjectDistance& distance,
                                  const SequenceData& data);

// The table's columns: the paper's Mul, Accel, Pen 1cm, Pen 5mm, then Pen 3mm and Depth (mm,
// the mean deepest penetration over contact frames), then Con, Art, CM, Implaus (ours:
// % of frames with an implausible hand) and Cavity (ours: % of frames with a hand inside a
// hollow part).
// `mul_per_trajectory` in metres (one value per trajectory with >= 2 samples). A column
// with nothing to average has value NaN and num_sequences 0.
std::vector<MetricResult> aggregate_metrics(const std::vector<SequenceMetrics>& sequences,
                                            const std::vector<double>& mul_per_trajectory);

// Single columns, for the plug-ins.
MetricResult mul_result(const std::vector<double>& mul_per_trajectory);
MetricResult accel_result(const std::vector<SequenceMetrics>& sequences);
MetricResult frame_share_result(const std::string& name, bool higher_is_better,
                                const std::vector<SequenceMetrics>& sequences,
                                FrameCount SequenceMetrics::*field);
MetricResult contact_map_result(const std::vector<SequenceMetrics>& sequences);
MetricResult contact_depth_result(const std::vector<SequenceMetrics>& sequences);

}  // namespace bimart
