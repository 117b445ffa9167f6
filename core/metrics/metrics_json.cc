#include "core/metrics/metrics_json.h"

#include <cmath>

namespace bimart {

namespace {
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json metrics_json(const MetricsSet& s) {
  nlohmann::json j;
  j["folder"] = s.folder;
  j["sequences"] = s.sequences.size();
  j["trajectories"] = s.trajectories;
  j["trajectories_with_samples"] = s.mul.size();
  j["skipped"] = nlohmann::json::array();
  for (const auto& [file, why] : s.skipped) j["skipped"].push_back({{"file", file}, {"error", why}});
  for (const auto& m : s.table) {
    nlohmann::json c{{"name", m.name}, {"value", number(m.value)}, {"unit", m.unit},
                     {"higher_is_better", m.higher_is_better}, {"num_sequences", m.num_sequences}};
    if (m.frame_share) {
      c["numerator"] = m.numerator;
      c["denominator"] = m.denominator;
    }
    j["metrics"].push_back(c);
  }
  for (size_t i = 0; i < s.sequences.size(); ++i) {
    const SequenceMetrics& m = s.sequences[i];
    auto count = [](const FrameCount& c) { return nlohmann::json::array({c.hits, c.frames}); };
    j["per_sequence"].push_back({{"file", i < s.files.size() ? s.files[i] : ""}, {"name", m.name}, {"frames", m.frames},
                                 {"accel_cm", number(100 * m.accel)}, {"pen_1cm", count(m.pen_1cm)},
                                 {"pen_5mm", count(m.pen_5mm)}, {"con", count(m.contact)},
                                 {"art", count(m.articulation)}, {"cm_cm", number(100 * m.contact_map)},
                                 {"pen_3mm", count(m.pen_3mm)}, {"implausible", count(m.implausible)}, {"cavity", count(m.cavity)},
                                 {"implausible_first", m.implausible_first}});
  }
  return j;
}

}  // namespace bimart
