// Reading a pipeline YAML into a GraphFile: structure only, with the location of every
// item. What the names mean is checked in graph_validate.cc.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/pipeline/graph.h"
#include "core/util/text.h"
#include "core/util/yaml_keys.h"

namespace fs = std::filesystem;

namespace bimart {

namespace {

SourceLocation at(const std::string& path, const YAML::Node& node) {
  const YAML::Mark m = node.Mark();
  if (m.line < 0) return SourceLocation{path, 0, 0};
  return SourceLocation{path, m.line + 1, m.column + 1};
}

class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& msg) const {
    throw Error(at(path_, node), msg);
  }

  std::string scalar(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) fail(node, what + " must be a single value");
    return node.Scalar();
  }

  void only_keys(const YAML::Node& map, const std::vector<std::string>& allowed,
                 const std::string& where) const {
    for (const auto& kv : map) {
      const std::string key = kv.first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(kv.first, "unknown key '" + key + "' in " + where + did_you_mean(key, allowed) +
                           "; allowed: " + join(allowed, ", "));
    }
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

StageSetting read_stage(const Reader& r, const YAML::Node& node, std::size_t index) {
  const std::string where = "stage #" + std::to_string(index + 1);
  if (!node.IsMap()) r.fail(node, where + " must be a mapping with 'id' and 'use'");
  r.only_keys(node, {"id", "use", "params", "inputs"}, where);
  StageSetting s;
  s.where = at(r.path(), node);
  if (!node["id"]) r.fail(node, where + " has no 'id'");
  if (!node["use"]) r.fail(node, where + " has no 'use' (the implementation, e.g. encoder.np_bps)");
  s.id = r.scalar(node["id"], "'id'");
  if (!is_lower_identifier(s.id))
    r.fail(node["id"], "stage id '" + s.id + "' must be lower case letters, digits and '_'");
  s.use = r.scalar(node["use"], "'use'");
  s.use_where = at(r.path(), node["use"]);
  if (const YAML::Node params = node["params"]) {
    if (!params.IsMap()) r.fail(params, "'params' of stage '" + s.id + "' must be a mapping");
    for (const auto& kv : params)
      s.params.push_back({kv.first.Scalar(), kv.second, at(r.path(), kv.first)});
  }
  if (const YAML::Node inputs = node["inputs"]) {
    if (!inputs.IsMap()) r.fail(inputs, "'inputs' of stage '" + s.id + "' must be a mapping");
    for (const auto& kv : inputs)
      s.inputs.push_back({kv.first.Scalar(),
                          r.scalar(kv.second, "input '" + kv.first.Scalar() + "'"),
                          at(r.path(), kv.second)});
  }
  return s;
}

}  // namespace

GraphFile GraphFile::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read pipeline file " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path, fs::path(path).parent_path().string());
}

GraphFile GraphFile::parse(const std::string& text, const std::string& path,
                           const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(SourceLocation{path, e.mark.line + 1, e.mark.column + 1}, "YAML syntax: " + e.msg);
  }
  check_duplicate_keys(text, path);
  const Reader r(path);
  if (!root.IsMap()) throw Error(SourceLocation{path, 1, 1}, "a pipeline must be a mapping with a 'stages' list");
  r.only_keys(root, {"name", "description", "seed", "plugins", "vars", "stages"}, "the pipeline");

  GraphFile g;
  g.path = path;
  g.name = root["name"] ? r.scalar(root["name"], "'name'") : fs::path(path).stem().string();
  if (root["description"]) g.description = r.scalar(root["description"], "'description'");
  if (const YAML::Node seed = root["seed"]) {
    try {
      g.seed = seed.as<std::uint64_t>();
    } catch (const YAML::Exception&) {
      r.fail(seed, "'seed' must be a non-negative integer, got '" + seed.Scalar() + "'");
    }
  }
  if (const YAML::Node plugins = root["plugins"]) {
    if (!plugins.IsSequence()) r.fail(plugins, "'plugins' must be a list of library paths");
    for (const auto& p : plugins) {
      fs::path lib = r.scalar(p, "a plug-in path");
      if (lib.is_relative() && !base_dir.empty()) lib = fs::path(base_dir) / lib;
      g.plugins.emplace_back(lib.lexically_normal().string(), at(path, p));
    }
  }
  if (const YAML::Node vars = root["vars"]) {
    if (!vars.IsMap()) r.fail(vars, "'vars' must be a mapping of variable names to default values");
    for (const auto& kv : vars) {
      const std::string name = r.scalar(kv.first, "a variable name");
      if (!is_lower_identifier(name))
        r.fail(kv.first, "variable name '" + name + "' must be lower case letters, digits and '_'");
      g.vars.push_back({name, kv.second, at(path, kv.second.IsNull() ? kv.first : kv.second), false});
    }
  }
  const YAML::Node stages = root["stages"];
  if (!stages) r.fail(root, "the pipeline has no 'stages' list");
  if (!stages.IsSequence() || stages.size() == 0) r.fail(stages, "'stages' must be a non-empty list");
  for (std::size_t i = 0; i < stages.size(); ++i) g.stages.push_back(read_stage(r, stages[i], i));
  return g;
}

void GraphFile::apply_override(const std::string& assignment) {
  const SourceLocation where{"--set " + assignment, 0, 0};
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(where, "an override must look like stage.param=value or seed=N");
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(where, "value is not valid YAML: " + e.msg);
  }
  if (key == "seed") {
    try {
      seed = value.as<std::uint64_t>();
    } catch (const YAML::Exception&) {
      throw Error(where, "seed must be a non-negative integer, got '" + text + "'");
    }
    return;
  }
  const auto dot = key.find('.');
  if (dot == std::string::npos)
    throw Error(where, "'" + key + "' names no stage parameter; write stage_id." + key + "=" + text);
  const std::string stage_id = key.substr(0, dot);
  const std::string param = key.substr(dot + 1);
  std::vector<std::string> ids;
  for (auto& s : stages) {
    ids.push_back(s.id);
    if (s.id != stage_id) continue;
    if (param == "use") {  // swap the implementation: stage_id.use=kind.name
      if (!value.IsScalar()) throw Error(where, "use= takes a registered stage name, e.g. encoder.u_bps");
      s.use = value.Scalar();
      s.use_where = where;
      return;
    }
    for (auto& p : s.params)
      if (p.name == param) {
        p.value = value;
        p.where = where;
        return;
      }
    s.params.push_back({param, value, where});
    return;
  }
  throw Error(where, "no stage '" + stage_id + "' in " + path + did_you_mean(stage_id, ids) +
                         "; stages: " + join(ids, ", "));
}

void GraphFile::set_var(const std::string& name, const std::string& value, const std::string& origin) {
  const SourceLocation where{origin, 0, 0};
  std::vector<std::string> names;
  for (auto& v : vars) {
    names.push_back(v.name);
    if (v.name != name) continue;
    try {
      v.value = YAML::Load(value);
    } catch (const YAML::Exception& e) {
      throw Error(where, "value is not valid YAML: " + e.msg);
    }
    v.where = where;
    v.set = true;
    return;
  }
  throw Error(where, path + " has no variable '" + name + "'" + did_you_mean(name, names) +
                         (names.empty() ? "; it declares none (vars:)" : "; its variables: " + join(names, ", ")));
}

void GraphFile::set_var(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(SourceLocation{"--var " + assignment, 0, 0}, "a variable must be set as name=value");
  set_var(assignment.substr(0, eq), assignment.substr(eq + 1), "--var " + assignment);
}

YAML::Node GraphFile::substitute(const YAML::Node& value) const {
  if (value.IsSequence() || value.IsMap()) {
    YAML::Node out = YAML::Clone(value);
    if (value.IsSequence())
      for (std::size_t i = 0; i < value.size(); ++i) out[i] = substitute(value[i]);
    else
      for (auto kv : out) kv.second = substitute(kv.second);
    return out;
  }
  if (!value.IsScalar() || value.Scalar().find('$') == std::string::npos) return value;
  const std::string& text = value.Scalar();
  auto lookup = [&](const std::string& name) -> const VarSetting& {
    std::vector<std::string> names;
    for (const auto& v : vars) {
      if (v.name == name) {
        if (v.value.IsNull())
          throw Error("variable '" + name + "' has no value: give it with --var " + name + "=VALUE");
        return v;
      }
      names.push_back(v.name);
    }
    throw Error("'${" + name + "}' names no variable of " + path + did_you_mean(name, names) +
                (names.empty() ? "; declare it under vars:" : "; its variables: " + join(names, ", ")));
  };
  // The whole value is one variable: keep its YAML value (an int stays an int).
  if (text.size() > 3 && text.compare(0, 2, "${") == 0 && text.back() == '}' &&
      text.find('}') == text.size() - 1)
    return YAML::Clone(lookup(text.substr(2, text.size() - 3)).value);
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, 3, "$${") == 0) {
      out += "${";
      i += 2;
    } else if (text.compare(i, 2, "${") == 0) {
      const auto end = text.find('}', i);
      if (end == std::string::npos) throw Error("'" + text + "': '${' without its closing '}'");
      const VarSetting& v = lookup(text.substr(i + 2, end - i - 2));
      if (!v.value.IsScalar())
        throw Error("variable '" + v.name + "' is a list or mapping; it can only stand alone, not inside '" + text + "'");
      out += v.value.Scalar();
      i = end;
    } else {
      out += text[i];
    }
  }
  return YAML::Node(out);
}

}  // namespace bimart
