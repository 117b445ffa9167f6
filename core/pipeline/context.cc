#include "core/pipeline/context.h"

namespace bimart {

std::vector<std::string> Context::keys() const {
  std::vector<std::string> out;
  out.reserve(slots_.size());
  for (const auto& kv : slots_) out.push_back(kv.first);
  return out;
}

const Context::Slot& Context::find(const std::string& key) const {
  auto it = slots_.find(key);
  if (it != slots_.end()) return it->second;
  const auto all = keys();
  throw Error("the context has no value '" + key + "'" + did_you_mean(key, all) +
              (all.empty() ? "; it is empty" : "; it holds: " + join(all, ", ")));
}

void Context::wrong_type(const std::string& key, const std::string& held, const std::string& wanted) {
  throw Error("context value '" + key + "' is of type '" + held + "', but was asked for as '" +
              wanted + "'");
}

}  // namespace bimart
