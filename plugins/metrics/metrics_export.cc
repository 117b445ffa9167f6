// export.metrics: the paper's metrics (DESIGN §6) over the run's samples as metrics.json,
// in the shape of `bimart eval --json` (core/metrics/metrics_json.h): Accel, Pen 1cm,
// Pen 5mm, Con, Art per sample and summed; CM where the contact maps are wired; Mul over
// the samples when there are at least two (all samples share one trajectory).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "core/metrics/hand_vertices.h"
#include "core/metrics/metrics_json.h"
#include "core/metrics/multimodality.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/object_distance.h"
#include "core/pipeline/plugin.h"
#include "core/util/atomic_file.h"
#include "core/util/log.h"
#include "core/util/parallel.h"
#include "metric_inputs.h"
#include "stages/exporter.h"
#include "stages/samples.h"

namespace bimart {
namespace {

class MetricsExport : public Exporter {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Exporter>("metrics", "the paper's metrics over the run's samples as a JSON file");
    declare_hand_object_inputs(s)
        .optional_input<at::Tensor>("contact_maps", "C: [N, 2, 1024] float32, m: the maps that conditioned sample 0 (CM)")
        .optional_input<at::Tensor>("basis_hit_indices", "[N, 1024] int64, from the encoder (CM)")
        .optional_input<std::vector<std::string>>("sequence_files",
                                                  "the sample files (e.g. export.sequence's paths), named per sample")
        .param("path", "out/metrics.json", "file to write (folders are created)")
        .param("name", "sample_{sample}", "name of each sample in the file ({sample}: its index)")
        .param("threads", 0, "samples evaluated at once (0: all cores)");
    declare_sample_ports(s);
    return s;
  }
  explicit MetricsExport(const Params& p)
      : path_(p.string("path")), name_(p.string("name")), threads_(static_cast<int>(p.integer("threads"))) {
    if (path_.empty()) throw Error("path must not be empty");
    if (threads_ < 0) throw Error("threads must be >= 0 (0: all cores)");
    sample_path(name_, 0);
  }

  void run(StageIO& io) override {
    const std::vector<StageSample> samples = stage_samples(io);
    const ArticulatedObject& object = io.in<ArticulatedObject>("object");
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const bool cm = io.has("basis_hit_indices");
    MetricsSet set;
    set.folder = std::filesystem::path(path_).parent_path().string();
    set.trajectories = 1;
    set.sequences.resize(samples.size());
    set.files.assign(samples.size(), "");
    if (io.has("sequence_files")) {
      const auto& files = io.in<std::vector<std::string>>("sequence_files");
      for (std::size_t k = 0; k < samples.size() && k < files.size(); ++k) set.files[k] = files[k];
    }
    std::vector<at::Tensor> vertices(samples.size());
    const ObjectDistance distance(object);
    parallel_for(samples.size(), resolve_threads(threads_), [&](std::size_t k) {
      SequenceData d;
      d.name = sample_path(name_, k);
      d.object_states = states;
      d.hand_vertices = vertices[k] = hand_vertices(*samples[k].hands);
      if (cm && samples[k].contact_maps.defined()) {
        d.hand_keypoints = hand_keypoints(*samples[k].hands);
        d.contact_maps = samples[k].contact_maps;
        d.basis_hit_indices = io.in<at::Tensor>("basis_hit_indices");
      }
      set.sequences[k] = evaluate_sequence(object, distance, d);
      set.sequences[k].name = d.name;
    });
    if (samples.size() >= 2) set.mul.push_back(multimodality(vertices));
    set.table = aggregate_metrics(set.sequences, set.mul);

    nlohmann::json j;
    j["samples"] = samples.size();
    j["frames"] = states.size(0);
    j["generated"] = metrics_json(set);
    write_file_atomically(path_, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::string line;
    for (const auto& m : set.table)
      if (std::isfinite(m.value)) line += fmt::format("{}{} {:.3g} {}", line.empty() ? "" : ", ", m.name, m.value, m.unit);
    log::info("metrics over {} sample{}: {}", samples.size(), samples.size() == 1 ? "" : "s", line);
    io.out("path", path_);
    io.out("paths", std::vector<std::string>{path_});
  }

 private:
  std::string path_, name_;
  int threads_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MetricsExport)
