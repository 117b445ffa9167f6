// The stage registry: "kind.name" -> spec + factory + the library that registered it.
// Lookups never return null: an unknown key is an error that lists the close names.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/pipeline/stage.h"

namespace bimart {

using StageFactory = std::function<std::unique_ptr<Stage>(const Params&)>;

struct StageEntry {
  StageSpec spec;
  StageFactory factory;
  std::string library;  // path of the plug-in library (or "<host>")
};

class Registry {
 public:
  // The process-wide registry the plug-in loader fills.
  static Registry& global();

  // Adds entries all at once: if any key is malformed or already registered (here or
  // earlier in `entries`), nothing is added and the error names both libraries.
  void add(std::vector<StageEntry> entries);
  void add(StageEntry entry);

  const StageEntry& get(const std::string& key) const;
  const StageEntry* find(const std::string& key) const;
  std::vector<std::string> keys() const;
  std::vector<const StageEntry*> entries() const;  // sorted by key
  std::size_t size() const { return entries_.size(); }
  void clear() { entries_.clear(); }

 private:
  std::map<std::string, StageEntry> entries_;
};

}  // namespace bimart
