// Stage parameters: a schema (name, type, default, one-line help) and validated values.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace bimart {

enum class ParamType { Bool, Int, Float, String, IntList, FloatList, StringList };

// "bool", "int", "float", "string", "int list", "float list", "string list".
const char* to_string(ParamType type);
// "a float", "an int", ...
std::string with_article(ParamType type);

using ParamValue = std::variant<bool, std::int64_t, double, std::string, std::vector<std::int64_t>,
                                std::vector<double>, std::vector<std::string>>;

ParamType type_of(const ParamValue& value);
// The value as YAML flow text, e.g. `64`, `0.5`, `"out.csv"`, `[1, 2]`.
std::string to_yaml(const ParamValue& value);

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::Float;
  ParamValue default_value;
  std::string help;
  // A string parameter whose value may also be written as a YAML list or mapping (in the
  // pipeline file or with --set); the stage gets its YAML flow text and parses it.
  bool yaml_text = false;
};

// Validated parameter values of one stage: every parameter of its schema is present
// (defaults filled in) and has the schema's type.
class Params {
 public:
  Params() = default;

  bool boolean(const std::string& name) const;
  std::int64_t integer(const std::string& name) const;
  double number(const std::string& name) const;
  const std::string& string(const std::string& name) const;
  const std::vector<std::int64_t>& integers(const std::string& name) const;
  const std::vector<double>& numbers(const std::string& name) const;
  const std::vector<std::string>& strings(const std::string& name) const;

  const ParamValue& value(const std::string& name) const;
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  void set(const std::string& name, ParamValue value) { values_[name] = std::move(value); }
  const std::map<std::string, ParamValue>& all() const { return values_; }

 private:
  template <class T>
  const T& typed(const std::string& name) const;

  std::map<std::string, ParamValue> values_;
};

}  // namespace bimart
