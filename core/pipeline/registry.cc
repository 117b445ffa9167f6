#include "core/pipeline/registry.h"

#include <set>

#include "core/util/error.h"
#include "core/util/text.h"

namespace bimart {

Registry& Registry::global() {
  static Registry registry;
  return registry;
}

void Registry::add(std::vector<StageEntry> entries) {
  std::map<std::string, const StageEntry*> incoming;
  for (const auto& e : entries) {
    try {
      e.spec.check();
    } catch (const Error& err) {
      throw Error(e.library + ": " + err.message());
    }
    if (auto it = entries_.find(e.spec.key); it != entries_.end())
      throw Error("duplicate stage '" + e.spec.key + "': registered by " + it->second.library +
                  " and again by " + e.library);
    if (auto [it, fresh] = incoming.emplace(e.spec.key, &e); !fresh)
      throw Error("duplicate stage '" + e.spec.key + "': registered twice by " + e.library);
  }
  for (auto& e : entries) {
    const std::string key = e.spec.key;
    entries_.emplace(key, std::move(e));
  }
}

void Registry::add(StageEntry entry) {
  std::vector<StageEntry> one;
  one.push_back(std::move(entry));
  add(std::move(one));
}

const StageEntry* Registry::find(const std::string& key) const {
  auto it = entries_.find(key);
  return it == entries_.end() ? nullptr : &it->second;
}

const StageEntry& Registry::get(const std::string& key) const {
  if (const StageEntry* e = find(key)) return *e;
  throw Error("no stage '" + key + "'" + did_you_mean(key, keys()) +
              "; `bimart plugins` lists the registered ones");
}

std::vector<std::string> Registry::keys() const {
  std::vector<std::string> out;
  for (const auto& kv : entries_) out.push_back(kv.first);
  return out;
}

std::vector<const StageEntry*> Registry::entries() const {
  std::vector<const StageEntry*> out;
  for (const auto& kv : entries_) out.push_back(&kv.second);
  return out;
}

}  // namespace bimart
