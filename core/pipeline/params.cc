#include "core/pipeline/params.h"

#include <sstream>

#include "core/util/error.h"
#include "core/util/text.h"

namespace bimart {

const char* to_string(ParamType type) {
  switch (type) {
    case ParamType::Bool: return "bool";
    case ParamType::Int: return "int";
    case ParamType::Float: return "float";
    case ParamType::String: return "string";
    case ParamType::IntList: return "int list";
    case ParamType::FloatList: return "float list";
    case ParamType::StringList: return "string list";
  }
  return "?";
}

std::string with_article(ParamType type) {
  const std::string name = to_string(type);
  return (name[0] == 'i' ? "an " : "a ") + name;
}

ParamType type_of(const ParamValue& value) { return static_cast<ParamType>(value.index()); }

namespace {

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string number_text(double x) {
  // Shortest of 15 or 17 significant digits that reads back exactly.
  std::ostringstream os;
  os.precision(15);
  os << x;
  if (std::stod(os.str()) != x) {
    os.str("");
    os.precision(17);
    os << x;
  }
  std::string s = os.str();
  // Keep floats recognisable as floats in YAML ("1" would read back as an int).
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

template <class T, class F>
std::string list_text(const std::vector<T>& items, F&& item) {
  std::vector<std::string> parts;
  for (const auto& x : items) parts.push_back(item(x));
  return "[" + join(parts, ", ") + "]";
}

}  // namespace

std::string to_yaml(const ParamValue& value) {
  switch (type_of(value)) {
    case ParamType::Bool: return std::get<bool>(value) ? "true" : "false";
    case ParamType::Int: return std::to_string(std::get<std::int64_t>(value));
    case ParamType::Float: return number_text(std::get<double>(value));
    case ParamType::String: return quoted(std::get<std::string>(value));
    case ParamType::IntList:
      return list_text(std::get<std::vector<std::int64_t>>(value),
                       [](std::int64_t x) { return std::to_string(x); });
    case ParamType::FloatList:
      return list_text(std::get<std::vector<double>>(value), number_text);
    case ParamType::StringList:
      return list_text(std::get<std::vector<std::string>>(value), quoted);
  }
  return "";
}

const ParamValue& Params::value(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) {
    std::vector<std::string> names;
    for (const auto& kv : values_) names.push_back(kv.first);
    throw Error("no parameter '" + name + "'" + did_you_mean(name, names));
  }
  return it->second;
}

template <class T>
const T& Params::typed(const std::string& name) const {
  const ParamValue& v = value(name);
  if (const T* x = std::get_if<T>(&v)) return *x;
  throw Error("parameter '" + name + "' is " + with_article(type_of(v)) + ", but was read as " +
              with_article(type_of(ParamValue(T{}))));
}

bool Params::boolean(const std::string& name) const { return typed<bool>(name); }
std::int64_t Params::integer(const std::string& name) const { return typed<std::int64_t>(name); }
double Params::number(const std::string& name) const { return typed<double>(name); }
const std::string& Params::string(const std::string& name) const {
  return typed<std::string>(name);
}
const std::vector<std::int64_t>& Params::integers(const std::string& name) const {
  return typed<std::vector<std::int64_t>>(name);
}
const std::vector<double>& Params::numbers(const std::string& name) const {
  return typed<std::vector<double>>(name);
}
const std::vector<std::string>& Params::strings(const std::string& name) const {
  return typed<std::vector<std::string>>(name);
}

}  // namespace bimart
