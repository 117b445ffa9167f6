// A stage: the unit the graph runs. Each implementation declares its contract once, in a
// static `spec()`: key "kind.name", help, parameters, input and output ports with types.
//
//   class ConstantTrajectory : public bimart::TrajectorySource {
//    public:
//     static bimart::StageSpec spec() {
//       return bimart::StageSpec::of<bimart::TrajectorySource>("constant", "One fixed state.")
//           .param("frames", 64, "number of frames");
//     }
//     explicit ConstantTrajectory(const bimart::Params& p);
//     void run(bimart::StageIO& io) override;
//   };
//   BIMART_REGISTER_STAGE(ConstantTrajectory)   // in the .cc file, see plugin.h
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/pipeline/context.h"
#include "core/pipeline/params.h"

namespace bimart {

struct PortSpec {
  std::string name;
  std::string type;  // type_name<T>() of the value
  std::string help;  // contract: shape, units, frame
  bool optional = false;
};

class StageSpec {
 public:
  std::string key;   // "kind.name", e.g. "encoder.np_bps"
  std::string help;  // one line
  std::vector<ParamSpec> params;
  std::vector<PortSpec> inputs;
  std::vector<PortSpec> outputs;

  StageSpec() = default;
  StageSpec(std::string key_, std::string help_) : key(std::move(key_)), help(std::move(help_)) {}

  // A spec for implementation `name` of stage kind `Kind`; the kind's ports (its
  // `static void declare(StageSpec&)`) come first.
  template <class Kind>
  static StageSpec of(const std::string& name, const std::string& help) {
    StageSpec s(std::string(Kind::kKind) + "." + name, help);
    Kind::declare(s);
    return s;
  }

  std::string kind() const { return key.substr(0, key.find('.')); }
  std::string name() const;

  StageSpec& param(const std::string& name, bool default_value, const std::string& help);
  StageSpec& param(const std::string& name, int default_value, const std::string& help);
  StageSpec& param(const std::string& name, std::int64_t default_value, const std::string& help);
  StageSpec& param(const std::string& name, double default_value, const std::string& help);
  StageSpec& param(const std::string& name, const char* default_value, const std::string& help);
  StageSpec& param(const std::string& name, const std::string& default_value, const std::string& help);
  StageSpec& param(const std::string& name, std::vector<std::int64_t> default_value, const std::string& help);
  StageSpec& param(const std::string& name, std::vector<double> default_value, const std::string& help);
  StageSpec& param(const std::string& name, std::vector<std::string> default_value, const std::string& help);
  // A string parameter that also takes a YAML list or mapping, handed over as its flow text
  // (ParamSpec::yaml_text); default "".
  StageSpec& yaml_param(const std::string& name, const std::string& help);

  template <class T>
  StageSpec& input(const std::string& name, const std::string& help) {
    return add_port(inputs, {name, type_name<T>(), help, false});
  }
  template <class T>
  StageSpec& optional_input(const std::string& name, const std::string& help) {
    return add_port(inputs, {name, type_name<T>(), help, true});
  }
  template <class T>
  StageSpec& output(const std::string& name, const std::string& help) {
    return add_port(outputs, {name, type_name<T>(), help, false});
  }

  const ParamSpec* find_param(const std::string& name) const;
  const PortSpec* find_input(const std::string& name) const;
  const PortSpec* find_output(const std::string& name) const;

  // Throws bimart::Error if the key is not "kind.name" (lower-case letters, digits, '_'),
  // or a parameter or port name appears twice.
  void check() const;

 private:
  StageSpec& add_param(const std::string& name, ParamValue default_value, const std::string& help);
  StageSpec& add_port(std::vector<PortSpec>& ports, PortSpec port);
};

class StageIO;

class Stage {
 public:
  virtual ~Stage() = default;
  // Reads inputs and writes every declared output through `io`. Throw bimart::Error for
  // anything a user can cause (bad input data, unwritable file).
  virtual void run(StageIO& io) = 0;
};

// What a running stage sees: its inputs and outputs by port name, its parameters, and a
// random generator seeded by the runner from the graph seed and the stage id (so a stage's
// stream does not change when other stages are added or removed).
class StageIO {
 public:
  StageIO(Context& context, const StageSpec& spec, std::string stage_id,
          std::vector<std::pair<std::string, std::string>> input_keys, const Params& params,
          std::uint64_t seed);

  template <class T>
  const T& in(const std::string& port) const {
    check_port(port, type_name<T>(), /*output=*/false);
    return context_.get<T>(input_key(port));
  }
  // True if an optional input is wired (required inputs always are).
  bool has(const std::string& port) const;
  // The id of the stage whose output feeds input `port` (for messages that name it).
  std::string source(const std::string& port) const;

  template <class T>
  void out(const std::string& port, T value) {
    check_port(port, type_name<T>(), /*output=*/true);
    context_.put<T>(output_key(port), std::move(value));
  }

  const Params& params() const { return params_; }
  const std::string& stage_id() const { return stage_id_; }
  std::uint64_t seed() const { return seed_; }
  std::mt19937_64& rng() { return rng_; }

  // Context key of an output port: "stage_id.port".
  std::string output_key(const std::string& port) const { return stage_id_ + "." + port; }

 private:
  void check_port(const std::string& port, const std::string& type, bool output) const;
  const std::string& input_key(const std::string& port) const;

  Context& context_;
  const StageSpec& spec_;
  std::string stage_id_;
  std::vector<std::pair<std::string, std::string>> input_keys_;  // port -> context key
  const Params& params_;
  std::uint64_t seed_;
  std::mt19937_64 rng_;
};

// Seed of a stage's generator: a hash of the graph seed and the stage id.
std::uint64_t stage_seed(std::uint64_t graph_seed, const std::string& stage_id);

}  // namespace bimart
