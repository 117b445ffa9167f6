#include "core/sweep/sweep_file.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>

#include "core/util/text.h"
#include "core/util/yaml_keys.h"

namespace bimart::sweep {
namespace {

struct Reader {
  std::string file;

  SourceLocation at(const YAML::Node& n) const { return yaml_location(file, n); }

  [[noreturn]] void fail(const YAML::Node& n, const std::string& msg) const { throw Error(at(n), msg); }

  void keys(const YAML::Node& n, const std::vector<std::string>& known, const std::string& what) const {
    if (!n.IsMap()) fail(n, what + " must be a map (key: value)");
    check_known_keys(n, known, file, what);
  }

  template <class T>
  void get(const YAML::Node& map, const char* key, T& out, const std::string& type) const {
    const YAML::Node v = map[key];
    if (!v) return;
    if (!v.IsScalar()) fail(v, std::string("'") + key + "' must be " + type);
    try {
      out = v.as<T>();
    } catch (const YAML::Exception&) {
      fail(v, std::string("'") + key + "' must be " + type + ", got '" + v.Scalar() + "'");
    }
  }

  // A map of overrides: key -> value kept as YAML text (flow style for lists and maps).
  std::vector<std::pair<std::string, std::string>> overrides(const YAML::Node& n, const std::string& what) const {
    std::vector<std::pair<std::string, std::string>> out;
    if (!n) return out;
    if (!n.IsMap()) fail(n, what + " must be a map (key: value)");
    for (const auto& kv : n) {
      YAML::Emitter e;
      e.SetMapFormat(YAML::Flow);
      e.SetSeqFormat(YAML::Flow);
      e << kv.second;
      out.emplace_back(kv.first.Scalar(), e.c_str());
    }
    return out;
  }
};

ModelSpec read_model(const Reader& r, const YAML::Node& n, const std::string& name) {
  ModelSpec m;
  m.name = name;
  m.where = r.at(n);
  r.keys(n, {"file", "train", "set", "nodes", "tasks_per_node", "cpus_per_task"}, "model '" + name + "'");
  r.get(n, "file", m.file, "a file name");
  r.get(n, "train", m.train, "a training config file name");
  m.set = r.overrides(n["set"], "'set' of model '" + name + "'");
  r.get(n, "nodes", m.nodes, "a positive integer");
  r.get(n, "tasks_per_node", m.tasks_per_node, "a positive integer");
  r.get(n, "cpus_per_task", m.cpus_per_task, "a non-negative integer");
  if (m.file.empty() == m.train.empty())
    r.fail(n, "model '" + name + "' needs exactly one of 'file' (a ready model) and 'train' (a training config)");
  if (!m.file.empty() && !m.set.empty()) r.fail(n["set"], "model '" + name + "': 'set' applies to 'train' configs only");
  if (m.nodes < 1 || m.tasks_per_node < 1 || m.cpus_per_task < 0)
    r.fail(n, "model '" + name + "': nodes and tasks_per_node must be positive, cpus_per_task not negative");
  return m;
}

}  // namespace

const std::vector<std::string>& metric_columns() {
  static const std::vector<std::string> c{"Mul", "Accel", "Pen 1cm", "Pen 5mm", "Pen 3mm", "Depth", "Con", "Art", "CM", "Implaus", "Cavity"};
  return c;
}

SweepFile SweepFile::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read the sweep file " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return parse(s.str(), path);
}

SweepFile SweepFile::parse(const std::string& text, const std::string& path) {
  check_duplicate_keys(text, path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(SourceLocation{path, e.mark.line + 1, e.mark.column + 1}, e.msg);
  }
  const Reader r{path};
  SweepFile f;
  f.path = path;
  if (!root.IsMap()) throw Error(SourceLocation{path, 1, 1}, "a sweep file is a map with base, models and rows");
  r.keys(root, {"name", "description", "base", "models", "rows"}, "the sweep file");
  r.get(root, "name", f.name, "text");
  r.get(root, "description", f.description, "text");
  if (f.name.empty()) throw Error(SourceLocation{path, 1, 1}, "'name' is required");

  const YAML::Node base = root["base"];
  if (!base) throw Error(SourceLocation{path, 1, 1}, "'base' is required (data, split, limit, samples, seed, pipeline)");
  r.keys(base, {"data", "split", "limit", "samples", "seed", "window", "pipeline", "output"}, "base");
  r.get(base, "data", f.base.data, "a data set folder");
  r.get(base, "split", f.base.split, "train or test");
  r.get(base, "limit", f.base.limit, "a non-negative integer");
  r.get(base, "samples", f.base.samples, "a positive integer");
  r.get(base, "seed", f.base.seed, "a non-negative integer");
  r.get(base, "window", f.base.window, "a positive integer");
  r.get(base, "pipeline", f.base.pipeline, "a pipeline file");
  r.get(base, "output", f.base.output, "an export stage id");
  if (f.base.data.empty()) r.fail(base, "'base.data' (the data set folder) is required");
  if (f.base.pipeline.empty()) r.fail(base, "'base.pipeline' is required");
  if (f.base.split != "train" && f.base.split != "test") r.fail(base["split"], "'split' must be train or test");
  if (f.base.limit < 0) r.fail(base["limit"], "'limit' must not be negative");
  if (f.base.samples < 1 || f.base.samples > 1000) r.fail(base["samples"], "'samples' must be in [1, 1000]");
  if (f.base.seed < 0) r.fail(base["seed"], "'seed' must not be negative");
  if (f.base.window < 2) r.fail(base["window"], "'window' must be at least 2");

  if (const YAML::Node models = root["models"]) {
    if (!models.IsMap()) r.fail(models, "'models' must be a map of model names");
    for (const auto& kv : models) {
      const std::string name = kv.first.Scalar();
      if (!is_lower_identifier(name)) r.fail(kv.first, "model name '" + name + "' must be [a-z_][a-z0-9_]*");
      f.models.push_back(read_model(r, kv.second, name));
    }
  }
  std::vector<std::string> model_names;
  for (const auto& m : f.models) model_names.push_back(m.name);

  const YAML::Node rows = root["rows"];
  if (!rows || !rows.IsSequence() || rows.size() == 0)
    throw Error(rows ? r.at(rows) : SourceLocation{path, 1, 1}, "'rows' must be a non-empty list of rows");
  std::set<std::string> row_names;
  for (const auto& n : rows) {
    RowSpec row;
    row.where = r.at(n);
    r.keys(n, {"name", "section", "pipeline", "output", "models", "set", "paper"}, "a row");
    r.get(n, "name", row.name, "text");
    if (row.name.empty()) r.fail(n, "every row needs a 'name'");
    if (row.name.find(',') != std::string::npos) r.fail(n["name"], "a row name must not contain ',' (--rows splits on it)");
    if (!row_names.insert(row.name).second) r.fail(n["name"], "row '" + row.name + "' is given twice");
    r.get(n, "section", row.section, "text");
    r.get(n, "pipeline", row.pipeline, "a pipeline file");
    r.get(n, "output", row.output, "an export stage id");
    if (const YAML::Node m = n["models"]) {
      if (!m.IsMap()) r.fail(m, "'models' of a row maps stage ids to model names");
      for (const auto& kv : m) {
        const std::string stage = kv.first.Scalar();
        if (kv.second.IsMap()) {  // an inline model
          ModelSpec inline_model = read_model(r, kv.second, row.name + "/" + stage);
          f.models.push_back(inline_model);
          row.models.emplace_back(stage, inline_model.name);
          continue;
        }
        if (!kv.second.IsScalar()) r.fail(kv.second, "a row's model is a name from 'models' or an inline {train: ...}");
        const std::string name = kv.second.Scalar();
        if (std::find(model_names.begin(), model_names.end(), name) == model_names.end())
          r.fail(kv.second, "no model '" + name + "' under 'models'" + did_you_mean(name, model_names) +
                                (model_names.empty() ? "" : " (known: " + join(model_names, ", ") + ")"));
        row.models.emplace_back(stage, name);
      }
    }
    row.set = r.overrides(n["set"], "'set' of row '" + row.name + "'");
    for (const auto& [k, v] : row.set)
      if (k.find('.') == std::string::npos && k != "seed")
        r.fail(n["set"], "row '" + row.name + "': override '" + k + "' must name a stage parameter (stage.param)");
    if (const YAML::Node p = n["paper"]) {
      r.keys(p, metric_columns(), "'paper' of row '" + row.name + "'");
      for (const auto& kv : p) {
        double v = 0;
        try {
          v = kv.second.as<double>();
        } catch (const YAML::Exception&) {
          r.fail(kv.second, "the paper's " + kv.first.Scalar() + " must be a number");
        }
        row.paper[kv.first.Scalar()] = v;
      }
    }
    f.rows.push_back(std::move(row));
  }
  return f;
}

const ModelSpec* SweepFile::find_model(const std::string& name) const {
  for (const auto& m : models)
    if (m.name == name) return &m;
  return nullptr;
}

void SweepFile::select_rows(const std::vector<std::string>& names) {
  if (names.empty()) return;
  std::vector<std::string> all;
  for (const auto& r : rows) all.push_back(r.name);
  std::vector<RowSpec> kept;
  for (const auto& n : names) {
    const auto it = std::find_if(rows.begin(), rows.end(), [&](const RowSpec& r) { return r.name == n; });
    if (it == rows.end())
      throw Error("--rows: no row '" + n + "' in " + path + did_you_mean(n, all) + " (rows: " + join(all, ", ") + ")");
    kept.push_back(*it);
  }
  rows = std::move(kept);
}

}  // namespace bimart::sweep
