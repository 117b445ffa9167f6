// The JSON form of a set of evaluated sequences, one shape for `bimart eval --json` and the
// metrics.json of export.metrics (docs/metrics.md): the table in the paper's column order
// with the counts behind each share, and the counts per sequence.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/metrics/sequence_metrics.h"

namespace bimart {

struct MetricsSet {
  std::string folder;                      // where the sequences are ("" when in memory)
  std::vector<std::string> files;          // per sequence; "" when not from a file
  std::vector<SequenceMetrics> sequences;
  std::vector<double> mul;                 // m, per trajectory with >= 2 samples
  std::size_t trajectories = 0;
  std::vector<MetricResult> table;         // aggregate_metrics(sequences, mul)
  std::vector<std::pair<std::string, std::string>> skipped;  // file, why (bimart eval --keep-going)
};

// {"folder", "sequences", "trajectories", "trajectories_with_samples", "skipped",
//  "metrics": [{name, value (null when undefined), unit, higher_is_better, num_sequences,
//  numerator, denominator}], "per_sequence": [{file, name, frames, accel_cm, pen_1cm,
//  pen_5mm, con, art (each [passing, considered]), cm_cm}]}
nlohmann::json metrics_json(const MetricsSet& set);

}  // namespace bimart
