// The typed context: named values that stages read and write while a graph runs.
// Keys are "stage_id.port" (the runner does the naming; stages speak in port names).
#pragma once

#include <any>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/pipeline/type_name.h"
#include "core/util/error.h"

namespace bimart {

class Context {
 public:
  // Stores (or replaces) a value under `key`.
  template <class T>
  void put(const std::string& key, T value) {
    slots_[key] = Slot{std::any(std::move(value)), type_name<T>()};
  }

  // The value under `key`. Throws bimart::Error naming the key and both types if the
  // value has another type, or naming the key and close keys if there is none.
  template <class T>
  const T& get(const std::string& key) const {
    const Slot& slot = find(key);
    const T* value = std::any_cast<T>(&slot.value);
    if (value == nullptr) wrong_type(key, slot.type, type_name<T>());
    return *value;
  }

  bool has(const std::string& key) const { return slots_.count(key) > 0; }
  // Readable type name of the value under `key` (throws if there is none).
  const std::string& type_of(const std::string& key) const { return find(key).type; }
  std::vector<std::string> keys() const;
  std::size_t size() const { return slots_.size(); }

 private:
  struct Slot {
    std::any value;
    std::string type;
  };

  const Slot& find(const std::string& key) const;
  [[noreturn]] static void wrong_type(const std::string& key, const std::string& held,
                                      const std::string& wanted);

  std::map<std::string, Slot> slots_;
};

}  // namespace bimart
