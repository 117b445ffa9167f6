#include "core/pipeline/stage.h"

#include <algorithm>
#include <set>

#include "core/util/error.h"
#include "core/util/text.h"

namespace bimart {

std::string StageSpec::name() const {
  const auto dot = key.find('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

StageSpec& StageSpec::add_param(const std::string& name, ParamValue default_value,
                                const std::string& help) {
  ParamSpec p;
  p.name = name;
  p.type = type_of(default_value);
  p.default_value = std::move(default_value);
  p.help = help;
  params.push_back(std::move(p));
  return *this;
}

StageSpec& StageSpec::param(const std::string& n, bool v, const std::string& h) { return add_param(n, v, h); }
StageSpec& StageSpec::param(const std::string& n, int v, const std::string& h) {
  return add_param(n, static_cast<std::int64_t>(v), h);
}
StageSpec& StageSpec::param(const std::string& n, std::int64_t v, const std::string& h) { return add_param(n, v, h); }
StageSpec& StageSpec::param(const std::string& n, double v, const std::string& h) { return add_param(n, v, h); }
StageSpec& StageSpec::param(const std::string& n, const char* v, const std::string& h) {
  return add_param(n, std::string(v), h);
}
StageSpec& StageSpec::param(const std::string& n, const std::string& v, const std::string& h) {
  return add_param(n, v, h);
}
StageSpec& StageSpec::param(const std::string& n, std::vector<std::int64_t> v, const std::string& h) {
  return add_param(n, std::move(v), h);
}
StageSpec& StageSpec::param(const std::string& n, std::vector<double> v, const std::string& h) {
  return add_param(n, std::move(v), h);
}
StageSpec& StageSpec::param(const std::string& n, std::vector<std::string> v, const std::string& h) {
  return add_param(n, std::move(v), h);
}

StageSpec& StageSpec::yaml_param(const std::string& n, const std::string& h) {
  add_param(n, std::string(), h);
  params.back().yaml_text = true;
  return *this;
}

StageSpec& StageSpec::add_port(std::vector<PortSpec>& ports, PortSpec port) {
  ports.push_back(std::move(port));
  return *this;
}

namespace {
template <class T>
const T* find_named(const std::vector<T>& items, const std::string& name) {
  for (const auto& x : items)
    if (x.name == name) return &x;
  return nullptr;
}
}  // namespace

const ParamSpec* StageSpec::find_param(const std::string& n) const { return find_named(params, n); }
const PortSpec* StageSpec::find_input(const std::string& n) const { return find_named(inputs, n); }
const PortSpec* StageSpec::find_output(const std::string& n) const { return find_named(outputs, n); }

void StageSpec::check() const {
  const auto dot = key.find('.');
  if (dot == std::string::npos || !is_lower_identifier(key.substr(0, dot), false) ||
      !is_lower_identifier(key.substr(dot + 1), false))
    throw Error("stage key '" + key + "' is not of the form kind.name (lower case, digits, '_')");
  auto unique = [&](const auto& items, const char* what) {
    std::set<std::string> seen;
    for (const auto& x : items)
      if (!seen.insert(x.name).second)
        throw Error("stage '" + key + "' declares " + what + " '" + x.name + "' twice");
  };
  unique(params, "parameter");
  unique(inputs, "input");
  unique(outputs, "output");
}

StageIO::StageIO(Context& context, const StageSpec& spec, std::string stage_id,
                 std::vector<std::pair<std::string, std::string>> input_keys, const Params& params,
                 std::uint64_t seed)
    : context_(context),
      spec_(spec),
      stage_id_(std::move(stage_id)),
      input_keys_(std::move(input_keys)),
      params_(params),
      seed_(seed),
      rng_(seed) {}

bool StageIO::has(const std::string& port) const {
  for (const auto& kv : input_keys_)
    if (kv.first == port) return true;
  return false;
}

std::string StageIO::source(const std::string& port) const {
  const std::string& key = input_key(port);  // "stage_id.port"
  return key.substr(0, key.find('.'));
}

const std::string& StageIO::input_key(const std::string& port) const {
  for (const auto& kv : input_keys_)
    if (kv.first == port) return kv.second;
  throw Error("stage '" + stage_id_ + "' (" + spec_.key + "): optional input '" + port +
              "' is not wired; check io.has(\"" + port + "\") first");
}

void StageIO::check_port(const std::string& port, const std::string& type, bool output) const {
  const auto& ports = output ? spec_.outputs : spec_.inputs;
  const PortSpec* p = output ? spec_.find_output(port) : spec_.find_input(port);
  const char* what = output ? "output" : "input";
  if (p == nullptr) {
    std::vector<std::string> names;
    for (const auto& x : ports) names.push_back(x.name);
    throw Error("stage '" + stage_id_ + "' (" + spec_.key + ") has no " + what + " '" + port + "'" +
                did_you_mean(port, names));
  }
  if (p->type != type)
    throw Error("stage '" + stage_id_ + "' (" + spec_.key + ") " + what + " '" + port +
                "' is declared as '" + p->type + "' but used as '" + type + "'");
}

std::uint64_t stage_seed(std::uint64_t graph_seed, const std::string& stage_id) {
  // FNV-1a of the id, mixed with the seed by splitmix64: stable across platforms and runs.
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : stage_id) {
    h ^= c;
    h *= 1099511628211ull;
  }
  std::uint64_t z = graph_seed ^ h;
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace bimart
