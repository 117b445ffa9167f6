#include "core/sweep/plan.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/data/manifest.h"
#include "core/diffusion/training.h"
#include "core/pipeline/graph.h"
#include "core/pipeline/registry.h"
#include "core/util/atomic_file.h"
#include "core/util/fingerprint.h"
#include "core/util/text.h"

namespace bimart::sweep {
namespace {

namespace fs = std::filesystem;

std::string read_text(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read " + what + " " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Sets "a.b.c" in a YAML map, creating the maps on the way.
void set_dotted(YAML::Node root, const std::string& key, const std::string& value_text) {
  YAML::Node value;
  try {
    value = YAML::Load(value_text);
  } catch (const YAML::Exception& e) {
    throw Error("'" + key + "': the value is not valid YAML: " + e.msg);
  }
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  // yaml-cpp nodes are handles: walk with fresh handles, never by assigning one to another.
  std::vector<YAML::Node> path{root};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = path.back()[parts[i]];
    if (next && !next.IsMap()) throw Error("'" + key + "': '" + parts[i] + "' is not a map in the config");
    if (!next) path.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
    path.push_back(path.back()[parts[i]]);
  }
  path.back()[parts.back()] = value;
}

std::string emit(const YAML::Node& n) {
  YAML::Emitter e;
  e << n;
  return e.c_str();
}

struct Planner {
  const SweepFile& file;
  Plan plan;
  std::map<std::string, std::size_t> by_key;           // job key -> index
  std::map<std::string, std::string> model_paths;      // model name -> the file the stage loads
  std::map<std::string, std::string> model_keys;       // model name -> key
  std::map<std::string, std::size_t> model_jobs;       // model name -> train job (absent for files)
  std::string data_fp;

  std::size_t add(Job job) {
    if (const auto it = by_key.find(job.key); it != by_key.end()) {
      Job& have = plan.jobs[it->second];
      if (have.name.find(job.name) == std::string::npos) have.name += ", " + job.name;
      return it->second;
    }
    plan.jobs.push_back(std::move(job));
    by_key[plan.jobs.back().key] = plan.jobs.size() - 1;
    return plan.jobs.size() - 1;
  }

  void plan_model(const ModelSpec& m) {
    const auto fail = [&](const std::string& msg) { throw Error(m.where, "model '" + m.name + "': " + msg); };
    if (!m.file.empty()) {
      if (!fs::is_regular_file(m.file)) fail("no model file " + m.file);
      model_paths[m.name] = m.file;
      model_keys[m.name] = file_fingerprint(m.file);
      return;
    }
    if (!fs::is_regular_file(m.train)) fail("no training config " + m.train);
    YAML::Node config;
    try {
      config = YAML::Load(read_text(m.train, "the training config"));
    } catch (const YAML::Exception& e) {
      fail(m.train + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
    }
    if (!config.IsMap()) fail(m.train + " is not a map");
    for (const auto& [k, v] : m.set) {
      try {
        set_dotted(config, k, v);
      } catch (const Error& e) {
        fail(std::string("set: ") + e.what());
      }
    }
    // The key: the config after overrides, without where it is written, with the data set
    // and any initial model by content.
    YAML::Node keyed = YAML::Clone(config);
    keyed.remove("out");
    keyed.remove("export");
    std::string init_fp;
    if (config["init"] && !config["init"].as<std::string>().empty()) init_fp = file_fingerprint(config["init"].as<std::string>());
    Fnv f;
    f.add("train");
    f.add(emit(keyed));
    f.add(init_fp);
    f.add(config["data"] ? dataset_fingerprint(config["data"].as<std::string>()) : std::string());
    // Each process draws `batch` windows a step: more processes train another model.
    // (One process adds nothing, so the keys of one-process models stay as they were.)
    const int world = m.nodes * m.tasks_per_node;
    if (world > 1) f.add("world " + std::to_string(world));
    Job job;
    job.kind = JobKind::Train;
    job.name = m.name;
    job.key = f.hex();
    job.folder = (fs::path(plan.dir) / "models" / job.key).string();
    config["out"] = job.folder;
    config["export"] = (fs::path(job.folder) / "model.npz").string();
    job.config_text = "# written by bimart sweep " + file.path + " (model " + m.name + ", from " + m.train + ")\n" +
                      emit(config) + "\n";
    // Checked now: a mistake in an override is reported before hours of other work.
    diffusion::TrainConfig tc;
    {
      const fs::path tmp = fs::temp_directory_path() / ("bimart-sweep-" + job.key + ".yaml");
      write_file_atomically(tmp.string(), [&](std::ostream& o) { o << job.config_text; });
      try {
        tc = diffusion::load_train_config(tmp.string());
      } catch (const Error& e) {
        fs::remove(tmp);
        std::string msg = e.what();
        if (msg.rfind(tmp.string(), 0) == 0) msg = "the config after overrides" + msg.substr(tmp.string().size());
        fail(msg);
      }
      fs::remove(tmp);
    }
    job.args = {"train", tc.model, (fs::path(job.folder) / "config.yaml").string()};
    job.result = (fs::path(job.folder) / "model.npz").string();
    job.work = static_cast<double>(tc.steps) * tc.batch * world;
    job.unit = "windows";
    job.rate_key = "train " + tc.model + " " + tc.network.describe();
    job.nodes = m.nodes;
    job.tasks_per_node = m.tasks_per_node;
    job.cpus_per_task = m.cpus_per_task;
    model_paths[m.name] = job.result;
    model_keys[m.name] = job.key;
    model_jobs[m.name] = add(std::move(job));
  }

  void plan_row(const RowSpec& row, std::size_t windows) {
    const auto fail = [&](const std::string& msg) { throw Error(row.where, "row '" + row.name + "': " + msg); };
    const std::string pipeline = row.pipeline.empty() ? file.base.pipeline : row.pipeline;
    const std::string output = row.output.empty() ? file.base.output : row.output;
    if (!fs::is_regular_file(pipeline)) fail("no pipeline " + pipeline);
    const std::string text = read_text(pipeline, "the pipeline");

    // Overrides as `bimart generate --set` takes them; models by path (in the command) and
    // by key (in the job's key).
    std::vector<std::string> sets, keyed_sets;
    std::vector<std::size_t> deps;
    for (const auto& [stage, model] : row.models) {
      sets.push_back(stage + ".checkpoint=" + model_paths.at(model));
      keyed_sets.push_back(stage + ".checkpoint=<" + model_keys.at(model) + ">");
      if (const auto it = model_jobs.find(model); it != model_jobs.end()) deps.push_back(it->second);
    }
    for (const auto& [k, v] : row.set) {
      sets.push_back(k + "=" + v);
      keyed_sets.push_back(k + "=" + v);
    }
    // The pipeline after the overrides must validate: names, types, the export stage.
    try {
      GraphFile g = GraphFile::parse(text, pipeline, fs::path(pipeline).parent_path().string());
      for (const auto& s : sets) g.apply_override(s);
      // "ground_truth": the windows' own hands, which bimart generate writes beside the samples.
      bool has_output = output == "ground_truth";
      for (const auto& st : g.stages) has_output |= st.id == output && st.use == "export.sequence";
      if (!has_output) {
        std::vector<std::string> exports;
        for (const auto& st : g.stages)
          if (st.use == "export.sequence") exports.push_back(st.id);
        throw Error("output '" + output + "' is no export.sequence stage of " + pipeline + did_you_mean(output, exports) +
                    " (export stages: " + join(exports, ", ") + ")");
      }
      validate(g, Registry::global());
    } catch (const Error& e) {
      fail(e.what());
    }

    Fnv g;
    g.add("generate");
    g.add(text);
    for (const auto& s : keyed_sets) g.add(s);
    g.add(data_fp);
    g.add(file.base.split);
    g.add_value(file.base.limit);
    g.add_value(file.base.samples);
    g.add_value(file.base.seed);
    g.add_value(file.base.window);
    Job gen;
    gen.kind = JobKind::Generate;
    gen.name = row.name;
    gen.key = g.hex();
    gen.folder = (fs::path(plan.dir) / "runs" / gen.key).string();
    gen.args = {"generate", file.base.data, "--split", file.base.split, "--samples", std::to_string(file.base.samples),
                "--seed", std::to_string(file.base.seed), "--window", std::to_string(file.base.window),
                "--pipeline", pipeline, "--out", gen.folder, "--resume"};
    if (file.base.limit > 0) gen.args.insert(gen.args.end(), {"--limit", std::to_string(file.base.limit)});
    for (const auto& s : sets) gen.args.insert(gen.args.end(), {"--set", s});
    gen.deps = deps;
    gen.result = (fs::path(gen.folder) / "generate.json").string();
    gen.work = static_cast<double>(windows) * file.base.samples;
    gen.unit = "window-samples";
    gen.rate_key = "generate " + pipeline;
    const std::size_t gi = add(std::move(gen));

    Fnv e;
    e.add("eval");
    e.add(plan.jobs[gi].key);
    e.add(output);
    Job ev;
    ev.kind = JobKind::Eval;
    ev.name = row.name;
    ev.key = e.hex();
    ev.folder = (fs::path(plan.dir) / "evals" / ev.key).string();
    ev.result = (fs::path(ev.folder) / "metrics.json").string();
    ev.args = {"eval", (fs::path(plan.jobs[gi].folder) / output).string(), "--json", ev.result};
    ev.deps = {gi};
    ev.work = static_cast<double>(windows) * file.base.samples;
    ev.unit = "sequences";
    ev.rate_key = "eval";
    const std::size_t ei = add(std::move(ev));

    RowPlan rp;
    rp.name = row.name;
    rp.section = row.section;
    rp.output = output;
    rp.generate = gi;
    rp.eval = ei;
    rp.paper = row.paper;
    plan.rows.push_back(rp);
  }
};

}  // namespace

std::string job_label(const Job& job) { return std::string(job_kind_name(job.kind)) + " " + job.name; }

const char* job_kind_name(JobKind kind) {
  switch (kind) {
    case JobKind::Train: return "train";
    case JobKind::Generate: return "generate";
    case JobKind::Eval: return "eval";
  }
  return "?";
}

Plan make_plan(const SweepFile& file, const std::string& dir) {
  Planner p{file, {}, {}, {}, {}, {}, {}};
  p.plan.sweep_file = file.path;
  p.plan.name = file.name;
  p.plan.dir = dir;
  if (!fs::is_directory(file.base.data))
    throw Error(file.path + ": base.data: no data set folder " + file.base.data + " (bimart data synth --out " +
                file.base.data + ")");
  p.data_fp = dataset_fingerprint(file.base.data);
  const DatasetManifest manifest = read_manifest(file.base.data);
  std::size_t windows = (file.base.split == "train" ? manifest.train : manifest.test).size();
  if (file.base.limit > 0) windows = std::min<std::size_t>(windows, static_cast<std::size_t>(file.base.limit));
  // Only the models some row uses.
  for (const auto& m : file.models) {
    bool used = false;
    for (const auto& r : file.rows)
      for (const auto& [stage, name] : r.models) used |= name == m.name;
    if (used) p.plan_model(m);
  }
  for (const auto& r : file.rows) p.plan_row(r, windows);
  return p.plan;
}

}  // namespace bimart::sweep
