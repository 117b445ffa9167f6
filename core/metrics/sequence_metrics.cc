#include "core/metrics/sequence_metrics.h"

#include <algorithm>
#include <cmath>

#include "core/metrics/accel.h"
#include "core/metrics/articulation.h"
#include "core/metrics/contact.h"
#include "core/metrics/contact_map_error.h"
#include "core/metrics/frame_depths.h"
#include "core/metrics/hand_plausibility.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/penetration.h"
#include "core/util/error.h"

namespace bimart {

SequenceMetrics evaluate_sequence(const ArticulatedObject& object, const ObjectDistance& distance,
                                  const SequenceData& d) {
  SequenceMetrics m;
  m.name = d.name;
  m.frames = d.object_states.size(0);
  FrameDepths depths;
  try {
    depths = frame_depths(distance, d.object_states, d.hand_vertices);
  } catch (const Error& e) {
    throw Error((d.name.empty() ? std::string() : "sequence '" + d.name + "', ") + e.message());
  }
  m.accel = mean_acceleration(d.hand_vertices);
  m.pen_1cm = penetration_frames(depths, kPenetration1cm);
  m.pen_5mm = penetration_frames(depths, kPenetration5mm);
  m.pen_3mm = penetration_frames(depths, kPenetration3mm);
  m.cavity = cavity_frames(depths);
  for (size_t t = 0; t < depths.size(); ++t) {
    if (depths.whole(t) <= -kContactDistance) continue;
    m.contact_depth_sum += std::max(depths.whole(t), 0.0);
    ++m.contact_depth_frames;
  }
  m.contact = contact_frames(depths, object_moving_frames(object, d.object_states));
  // Needs the hand model's vertices (the joints are regressed from them); other point sets
  // (tests' few points) leave it unmeasured.
  const auto hands = posing_hand_models();
  if (d.hand_vertices.size(2) == (*hands)[0].j_regressor.cols())
    m.implausible = implausible_frames(d.hand_vertices, {&(*hands)[0], &(*hands)[1]}, &m.implausible_first);
  m.articulation = articulation_frames(depths, angle_changing_frames(d.object_states));
  if (d.contact_maps.defined() && d.basis_hit_indices.defined() && d.hand_keypoints.defined())
    m.contact_map = contact_map_error(object, d.object_states, d.basis_hit_indices, d.hand_keypoints,
                                      d.contact_maps);
  return m;
}

namespace {

MetricResult mean_result(const char* name, const char* unit, bool higher, const std::vector<double>& values) {
  MetricResult r;
  r.name = name;
  r.unit = unit;
  r.higher_is_better = higher;
  double sum = 0;
  for (double v : values)
    if (std::isfinite(v)) {
      sum += v;
      ++r.num_sequences;
    }
  r.value = r.num_sequences ? 100.0 * sum / static_cast<double>(r.num_sequences)
                            : std::numeric_limits<double>::quiet_NaN();
  return r;
}

}  // namespace

MetricResult mul_result(const std::vector<double>& mul) { return mean_result("Mul", "cm", true, mul); }

MetricResult accel_result(const std::vector<SequenceMetrics>& s) {
  std::vector<double> v;
  for (const auto& m : s) v.push_back(m.accel);
  return mean_result("Accel", "cm/frame²", false, v);
}

MetricResult contact_map_result(const std::vector<SequenceMetrics>& s) {
  std::vector<double> v;
  for (const auto& m : s) v.push_back(m.contact_map);
  return mean_result("CM", "cm", false, v);
}

MetricResult contact_depth_result(const std::vector<SequenceMetrics>& s) {
  MetricResult r;
  r.name = "Depth";
  r.unit = "mm";
  r.higher_is_better = false;
  double sum = 0;
  std::int64_t frames = 0;
  for (const auto& m : s) {
    sum += m.contact_depth_sum;
    frames += m.contact_depth_frames;
  }
  r.num_sequences = static_cast<std::int64_t>(s.size());
  r.value = frames ? 1000.0 * sum / static_cast<double>(frames) : std::numeric_limits<double>::quiet_NaN();
  return r;
}

MetricResult frame_share_result(const std::string& name, bool higher,
                                const std::vector<SequenceMetrics>& s, FrameCount SequenceMetrics::*field) {
  MetricResult r;
  r.name = name;
  r.unit = "%";
  r.higher_is_better = higher;
  r.frame_share = true;
  for (const auto& m : s) {
    r.numerator += (m.*field).hits;
    r.denominator += (m.*field).frames;
  }
  r.num_sequences = static_cast<std::int64_t>(s.size());
  r.value = r.denominator ? 100.0 * static_cast<double>(r.numerator) / static_cast<double>(r.denominator)
                          : std::numeric_limits<double>::quiet_NaN();
  return r;
}

std::vector<MetricResult> aggregate_metrics(const std::vector<SequenceMetrics>& s,
                                            const std::vector<double>& mul) {
  return {mul_result(mul),
          accel_result(s),
          frame_share_result("Pen 1cm", false, s, &SequenceMetrics::pen_1cm),
          frame_share_result("Pen 5mm", false, s, &SequenceMetrics::pen_5mm),
          frame_share_result("Pen 3mm", false, s, &SequenceMetrics::pen_3mm),
          contact_depth_result(s),
          frame_share_result("Con", true, s, &SequenceMetrics::contact),
          frame_share_result("Art", true, s, &SequenceMetrics::articulation),
          contact_map_result(s),
          frame_share_result("Implaus", false, s, &SequenceMetrics::implausible),
          frame_share_result("Cavity", false, s, &SequenceMetrics::cavity)};
}

}  // namespace bimart
