// A sweep file (docs/sweeps.md): the rows of an ablation table as variants of one
// evaluation run. `base` fixes the data set, the evaluation windows and the default
// pipeline; `models` names diffusion models (a file, or a training config with
// overrides); each row picks a pipeline, stage overrides, the models of its stages and the
// paper's numbers for it.
//
//   name: table3
//   base: {data: data/synth, split: test, limit: 100, samples: 10, seed: 0,
//          pipeline: pipelines/generate_eval_fit.yaml, output: guided}
//   models:
//     u_bps_contact: {train: models/contact.yaml, set: {variant: u_bps}}
//     shipped_motion: {file: models/motion.npz}
//   rows:
//     - name: U-BPS
//       section: Rep
//       models: {contact: u_bps_contact, motion: u_bps_motion}   # stage id: model
//       set: {encoder.use: encoder.u_bps}                        # stage.param: value
//       paper: {Mul: 6.2551, Accel: 0.28275, Pen 1cm: 17.542, Con: 97.214, Art: 85.642, CM: 1.1072}
//
// Every mistake is an Error naming the file, line and column, with the nearest valid key.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/util/error.h"

namespace bimart::sweep {

// The metric columns of a table, in order, as `bimart eval --json` names them.
const std::vector<std::string>& metric_columns();

struct ModelSpec {
  std::string name;        // key under `models:` (or "<row>/<stage>" when given inline)
  std::string file;        // a ready model (.npz): used as is
  std::string train;       // or a training config (bimart train) ...
  std::vector<std::pair<std::string, std::string>> set;  // ... with overrides "a.b" -> YAML text
  int nodes = 1, tasks_per_node = 1, cpus_per_task = 0;   // for cluster backends (0 = default)
  SourceLocation where;
};

struct RowSpec {
  std::string name;
  std::string section;
  std::string pipeline;  // "" = base.pipeline
  std::string output;    // export stage whose sequences are evaluated; "" = base.output
  std::vector<std::pair<std::string, std::string>> models;  // stage id -> model name
  std::vector<std::pair<std::string, std::string>> set;     // "stage.param" -> YAML text
  std::map<std::string, double> paper;                      // metric column -> value
  SourceLocation where;
};

struct SweepBase {
  std::string data;
  std::string split = "test";
  long long limit = 0;  // 0 = every window of the split
  int samples = 10;
  long long seed = 0;
  int window = 64;
  std::string pipeline;
  std::string output = "refined";
};

struct SweepFile {
  std::string path;
  std::string name;
  std::string description;
  SweepBase base;
  std::vector<ModelSpec> models;
  std::vector<RowSpec> rows;

  // Reads and checks a sweep file. Relative paths (data, pipelines, configs, model files)
  // are taken relative to the current folder, as every bimart command does.
  static SweepFile load(const std::string& path);
  static SweepFile parse(const std::string& text, const std::string& path);

  const ModelSpec* find_model(const std::string& name) const;
  // Keeps only the named rows (comma-separated names as `--rows` gives them); an unknown
  // name is an error with the closest names.
  void select_rows(const std::vector<std::string>& names);
};

}  // namespace bimart::sweep
