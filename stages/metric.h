// Stage kind "metric": computes one of the paper's metrics (DESIGN §6) on generated or
// ground-truth motion. Each implementation declares the inputs it needs (hand motion,
// object, trajectory, contact maps, several samples); all write one MetricResult.
#pragma once

#include <cstdint>
#include <string>

#include "core/pipeline/stage.h"

namespace bimart {

struct MetricResult {
  std::string name;              // as in the paper's tables: "Accel", "Pen 1cm", "Con", ...
  double value = 0.0;            // in `unit`, the ×100 of DESIGN §6 applied; NaN if undefined
  std::string unit;              // "cm", "%", "cm/frame²"
  bool higher_is_better = false; // the table's ↑ / ↓

  // Frame shares (Pen, Con, Art): frames that pass and frames considered, summed over all
  // sequences; value = 100 · numerator / denominator. Other metrics leave them at 0.
  bool frame_share = false;
  std::int64_t numerator = 0;
  std::int64_t denominator = 0;

  std::int64_t num_sequences = 0;  // sequences (trajectories, for Mul) evaluated
};

class Metric : public Stage {
 public:
  static constexpr const char* kKind = "metric";

  static void declare(StageSpec& s) {
    s.output<MetricResult>("result", "the metric's value with its unit and counts");
  }
};

}  // namespace bimart
