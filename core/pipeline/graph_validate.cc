// Validating a GraphFile against the registry: implementations, parameters, wiring, types
// and order. All problems are collected and reported together, each with its location.
#include <algorithm>
#include <functional>
#include <map>
#include <set>

#include "core/pipeline/graph.h"
#include "core/util/text.h"

namespace bimart {

namespace {

class Problems {
 public:
  void add(const SourceLocation& where, const std::string& msg) { items_.emplace_back(where, msg); }
  bool empty() const { return items_.empty(); }

  void throw_if_any() const {
    if (items_.empty()) return;
    if (items_.size() == 1) throw items_.front();
    std::string msg = std::to_string(items_.size()) + " problems in the pipeline:";
    for (const auto& e : items_) msg += "\n  " + std::string(e.what());
    throw Error(msg);
  }

 private:
  std::vector<Error> items_;
};

// Converts a YAML value to the parameter's type; throws a message (without location).
ParamValue convert(const YAML::Node& node, ParamType type, bool yaml_text) {
  if (yaml_text && (node.IsMap() || node.IsSequence())) {
    YAML::Emitter flow;
    flow.SetMapFormat(YAML::Flow);
    flow.SetSeqFormat(YAML::Flow);
    flow << node;
    return std::string(flow.c_str());
  }
  auto scalar_text = [&]() -> std::string {
    if (node.IsNull()) throw std::runtime_error("has no value");
    if (!node.IsScalar()) throw std::runtime_error("expects " + with_article(type) + ", got a list or mapping");
    return node.Scalar();
  };
  auto as = [&](const YAML::Node& n, ParamType t) -> ParamValue {
    const std::string text = n.IsScalar() ? n.Scalar() : "";
    try {
      if (!n.IsScalar()) throw YAML::Exception(YAML::Mark(), "");
      switch (t) {
        case ParamType::Bool: return n.as<bool>();
        case ParamType::Int: return n.as<std::int64_t>();
        case ParamType::Float: return n.as<double>();
        default: return n.Scalar();
      }
    } catch (const YAML::Exception&) {
      throw std::runtime_error("expects " + with_article(t) + ", got '" + text + "'");
    }
  };
  switch (type) {
    case ParamType::Bool:
    case ParamType::Int:
    case ParamType::Float:
    case ParamType::String:
      scalar_text();
      return as(node, type);
    case ParamType::IntList:
    case ParamType::FloatList:
    case ParamType::StringList: {
      if (!node.IsSequence())
        throw std::runtime_error("expects " + with_article(type) + " like [1, 2]");
      const ParamType item = type == ParamType::IntList     ? ParamType::Int
                             : type == ParamType::FloatList ? ParamType::Float
                                                            : ParamType::String;
      std::vector<std::int64_t> ints;
      std::vector<double> floats;
      std::vector<std::string> strings;
      for (const auto& x : node) {
        const ParamValue v = as(x, item);
        if (item == ParamType::Int) ints.push_back(std::get<std::int64_t>(v));
        if (item == ParamType::Float) floats.push_back(std::get<double>(v));
        if (item == ParamType::String) strings.push_back(std::get<std::string>(v));
      }
      if (item == ParamType::Int) return ints;
      if (item == ParamType::Float) return floats;
      return strings;
    }
  }
  return {};
}

std::string describe_stage(const StageSetting& s) { return "stage '" + s.id + "'"; }

std::vector<std::string> port_names(const std::vector<PortSpec>& ports) {
  std::vector<std::string> out;
  for (const auto& p : ports) out.push_back(p.name);
  return out;
}

}  // namespace

Graph validate(const GraphFile& file, const Registry& registry) {
  Problems problems;
  const auto& settings = file.stages;
  std::map<std::string, std::size_t> index_of;  // id -> first position in the file
  std::vector<const StageEntry*> entries(settings.size(), nullptr);

  // 1. ids, implementations, parameters.
  std::vector<GraphNode> nodes(settings.size());
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const StageSetting& s = settings[i];
    GraphNode& n = nodes[i];
    n.id = s.id;
    n.where = s.where;
    if (auto [it, fresh] = index_of.emplace(s.id, i); !fresh)
      problems.add(s.where, "duplicate stage id '" + s.id + "' (first used at " +
                                settings[it->second].where.str() + ")");
    entries[i] = registry.find(s.use);
    if (entries[i] == nullptr) {
      problems.add(s.use_where, describe_stage(s) + " uses unknown implementation '" + s.use + "'" +
                                    did_you_mean(s.use, registry.keys()) +
                                    "; `bimart plugins` lists the registered ones");
      continue;
    }
    n.entry = entries[i];
    const StageSpec& spec = n.entry->spec;
    for (const auto& p : spec.params) n.params.set(p.name, p.default_value);
    for (const auto& p : s.params) {
      const ParamSpec* ps = spec.find_param(p.name);
      if (ps == nullptr) {
        std::vector<std::string> names;
        for (const auto& x : spec.params) names.push_back(x.name);
        problems.add(p.where, describe_stage(s) + " (" + spec.key + ") has no parameter '" + p.name +
                                  "'" + did_you_mean(p.name, names) +
                                  (names.empty() ? "; it takes none" : "; it takes: " + join(names, ", ")));
        continue;
      }
      const SourceLocation w = p.value.Mark().line >= 0 && p.where.line > 0
                                   ? SourceLocation{p.where.file, p.value.Mark().line + 1,
                                                    p.value.Mark().column + 1}
                                   : p.where;
      YAML::Node value;
      try {
        value = file.substitute(p.value);
      } catch (const Error& e) {
        problems.add(w, describe_stage(s) + " parameter '" + p.name + "': " + e.message());
        continue;
      }
      try {
        n.params.set(p.name, convert(value, ps->type, ps->yaml_text));
      } catch (const std::runtime_error& e) {
        const bool substituted = value.IsScalar() && p.value.IsScalar() && value.Scalar() != p.value.Scalar();
        problems.add(w, describe_stage(s) + " parameter '" + p.name + "' " + e.what() +
                            (substituted ? " (from '" + p.value.Scalar() + "')" : ""));
      }
    }
  }
  problems.throw_if_any();

  // 2. wiring: explicit inputs, then the nearest earlier producer of the same name.
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const StageSetting& s = settings[i];
    GraphNode& n = nodes[i];
    const StageSpec& spec = n.entry->spec;
    std::set<std::string> bound;
    for (const auto& in : s.inputs) {
      const PortSpec* port = spec.find_input(in.port);
      if (port == nullptr) {
        problems.add(in.where, describe_stage(s) + " (" + spec.key + ") has no input '" + in.port +
                                   "'" + did_you_mean(in.port, port_names(spec.inputs)));
        continue;
      }
      const auto dot = in.source.find('.');
      if (dot == std::string::npos) {
        problems.add(in.where, "input '" + in.port + "' of " + describe_stage(s) +
                                   " must name its source as stage_id.output, got '" + in.source + "'");
        continue;
      }
      const std::string from = in.source.substr(0, dot);
      const std::string output = in.source.substr(dot + 1);
      auto it = index_of.find(from);
      if (it == index_of.end()) {
        std::vector<std::string> ids;
        for (const auto& x : settings) ids.push_back(x.id);
        problems.add(in.where, "input '" + in.port + "' of " + describe_stage(s) + " comes from stage '" +
                                   from + "', which is not in the pipeline" + did_you_mean(from, ids));
        continue;
      }
      const StageSpec& producer = nodes[it->second].entry->spec;
      const PortSpec* out = producer.find_output(output);
      if (out == nullptr) {
        problems.add(in.where, "input '" + in.port + "' of " + describe_stage(s) + ": stage '" + from +
                                   "' (" + producer.key + ") produces no '" + output + "'" +
                                   did_you_mean(output, port_names(producer.outputs)) + "; it produces: " +
                                   join(port_names(producer.outputs), ", "));
        continue;
      }
      if (out->type != port->type) {
        problems.add(in.where, "input '" + in.port + "' of " + describe_stage(s) + " expects '" +
                                   port->type + "', but " + in.source + " is '" + out->type + "'");
        continue;
      }
      bound.insert(in.port);
      n.inputs.push_back({in.port, from, output, false, in.where});
    }
    for (const auto& port : spec.inputs) {
      if (bound.count(port.name)) continue;
      if (std::any_of(s.inputs.begin(), s.inputs.end(), [&](const auto& x) { return x.port == port.name; }))
        continue;  // wired explicitly but wrongly: already reported
      // Nearest earlier stage with an output of this name and type; a same-named output
      // of another type is reported only if no stage offers the right type.
      std::size_t found = settings.size(), same_name = settings.size();
      for (std::size_t j = i; j-- > 0;)
        if (const PortSpec* out = nodes[j].entry->spec.find_output(port.name)) {
          if (same_name == settings.size()) same_name = j;
          if (out->type == port.type) {
            found = j;
            break;
          }
        }
      if (found < settings.size()) {
        n.inputs.push_back({port.name, nodes[found].id, port.name, true, s.where});
        continue;
      }
      if (same_name < settings.size()) {
        problems.add(s.where, "input '" + port.name + "' of " + describe_stage(s) + " expects '" +
                                  port.type + "', but the earlier stage producing it, '" +
                                  nodes[same_name].id + "', gives '" +
                                  nodes[same_name].entry->spec.find_output(port.name)->type + "'");
        continue;
      }
      if (port.optional) continue;
      std::vector<std::string> later;
      for (std::size_t j = i + 1; j < settings.size(); ++j)
        if (nodes[j].entry->spec.find_output(port.name)) later.push_back("'" + nodes[j].id + "'");
      if (!later.empty())
        problems.add(s.where, describe_stage(s) + " (" + spec.key + ") needs input '" + port.name +
                                  "', but no earlier stage produces it (only later " + join(later, ", ") +
                                  "); move the stage or wire it under inputs:");
      else
        problems.add(s.where, describe_stage(s) + " (" + spec.key + ") is missing input '" + port.name +
                                  "' (" + port.type + ": " + port.help +
                                  "); no stage produces it: add one that does or wire it under inputs:");
    }
  }
  problems.throw_if_any();

  // 3. order: dependencies first, otherwise file order; whatever remains lies on a cycle.
  const std::size_t count = nodes.size();
  std::vector<std::set<std::size_t>> deps(count);
  for (std::size_t i = 0; i < count; ++i)
    for (const auto& b : nodes[i].inputs) deps[i].insert(index_of.at(b.stage_id));
  std::vector<bool> done(count, false);
  std::vector<std::size_t> order;
  while (order.size() < count) {
    std::size_t next = count;
    for (std::size_t i = 0; i < count && next == count; ++i)
      if (!done[i] && std::all_of(deps[i].begin(), deps[i].end(), [&](std::size_t d) { return done[d]; }))
        next = i;
    if (next == count) break;
    done[next] = true;
    order.push_back(next);
  }
  if (order.size() < count) {
    // Walk dependencies from a stuck node until a node repeats: that is a cycle.
    std::size_t start = 0;
    while (done[start]) ++start;
    std::vector<std::size_t> path{start};
    for (;;) {
      std::size_t cur = path.back(), next = count;
      for (std::size_t d : deps[cur])
        if (!done[d]) {
          next = d;
          break;
        }
      auto seen = std::find(path.begin(), path.end(), next);
      if (seen != path.end()) {
        std::vector<std::string> names;
        for (auto it = seen; it != path.end(); ++it) names.push_back(nodes[*it].id);
        names.push_back(nodes[next].id);
        std::reverse(names.begin(), names.end());
        problems.add(nodes[next].where, "the stages form a cycle: " + join(names, " -> "));
        break;
      }
      path.push_back(next);
    }
    problems.throw_if_any();
  }

  Graph g;
  g.path = file.path;
  g.name = file.name;
  g.description = file.description;
  g.seed = file.seed;
  for (const auto& v : file.vars) g.vars.emplace_back(v.name, v.value.IsNull() ? "" : YAML::Dump(v.value));
  for (std::size_t i : order) g.nodes.push_back(std::move(nodes[i]));
  return g;
}

const GraphNode& Graph::node(const std::string& id) const {
  for (const auto& n : nodes)
    if (n.id == id) return n;
  throw Error("no stage '" + id + "' in pipeline " + name);
}

std::string Graph::describe() const {
  std::string s = "pipeline '" + name + "' (" + path + "), seed " + std::to_string(seed) + "\n";
  if (!description.empty()) s += "  " + description + "\n";
  if (!vars.empty()) {
    std::vector<std::string> parts;
    for (const auto& [name, value] : vars) parts.push_back(name + " = " + (value.empty() ? "(none)" : value));
    s += "  vars: " + join(parts, ", ") + "\n";
  }
  int k = 0;
  for (const auto& n : nodes) {
    const StageSpec& spec = n.entry->spec;
    s += "\n" + std::to_string(++k) + ". " + n.id + "  [" + spec.key + "]  " + spec.help + "\n";
    s += "   library: " + n.entry->library + "\n";
    for (const auto& kv : n.params.all()) s += "   param  " + kv.first + " = " + to_yaml(kv.second) + "\n";
    for (const auto& b : n.inputs)
      s += "   in     " + b.port + " <- " + b.stage_id + "." + b.output + (b.implicit ? "  (by name)" : "") + "\n";
    for (const auto& o : spec.outputs) s += "   out    " + o.name + " : " + o.type + "\n";
  }
  return s;
}

std::string Graph::mermaid() const {
  std::string s = "flowchart LR\n";
  for (const auto& n : nodes) s += "  " + n.id + "[\"" + n.id + "<br/>" + n.entry->spec.key + "\"]\n";
  for (const auto& n : nodes)
    for (const auto& b : n.inputs) s += "  " + b.stage_id + " -- " + b.output + " --> " + n.id + "\n";
  return s;
}

}  // namespace bimart
