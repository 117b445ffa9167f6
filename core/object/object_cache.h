// Objects by resolved path, each loaded (core/object/object_io.h) and its distance trees
// built (core/object/object_distance.h) once, then shared read-only by threads. For tools
// that walk many sequence files over few objects (`bimart eval`, `bimart data check`).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"

namespace bimart {

class ObjectCache {
 public:
  struct Entry {
    ArticulatedObject object;
    std::unique_ptr<ObjectDistance> distance;
  };
  // Loads on first use; other threads asking for the same path wait for that load.
  // Throws what load_object throws.
  std::shared_ptr<const Entry> get(const std::string& path);

 private:
  std::mutex mutex_;
  std::map<std::string, std::pair<std::shared_ptr<std::once_flag>, std::shared_ptr<Entry>>> entries_;
};

}  // namespace bimart
