#include "core/object/object_cache.h"

#include "core/object/object_io.h"

namespace bimart {

std::shared_ptr<const ObjectCache::Entry> ObjectCache::get(const std::string& path) {
  std::shared_ptr<std::once_flag> once;
  std::shared_ptr<Entry> entry;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto& slot = entries_[path];
    if (!slot.second) slot = {std::make_shared<std::once_flag>(), std::make_shared<Entry>()};
    once = slot.first;
    entry = slot.second;
  }
  std::call_once(*once, [&] {  // outside the lock: other objects load meanwhile
    entry->object = load_object(path);
    entry->distance = std::make_unique<ObjectDistance>(entry->object);
  });
  return entry;
}

}  // namespace bimart
