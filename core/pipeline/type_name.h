// Readable names for the C++ types that travel through the context and stage ports.
// Ports are matched by these names at graph validation, so they must be the same in every
// library: common types get a short name here, every other type its demangled C++ name.
#pragma once

#include <cstdint>
#include <string>
#include <typeinfo>
#include <vector>

#include "core/util/text.h"

namespace bimart {

template <class T>
struct TypeName {
  static std::string get() { return demangle(typeid(T).name()); }
};

#define BIMART_SHORT_TYPE_NAME(Type, Name) \
  template <>                              \
  struct TypeName<Type> {                  \
    static std::string get() { return Name; } \
  };

BIMART_SHORT_TYPE_NAME(bool, "bool")
// Ports and parameters use int64 ("int") and double ("float"); the narrower C++ types get
// names of their own so that a mix-up is caught at validation, not when the value is read.
BIMART_SHORT_TYPE_NAME(int, "int32")
BIMART_SHORT_TYPE_NAME(float, "float32")
BIMART_SHORT_TYPE_NAME(std::int64_t, "int")
BIMART_SHORT_TYPE_NAME(double, "float")
BIMART_SHORT_TYPE_NAME(std::string, "string")
BIMART_SHORT_TYPE_NAME(std::vector<std::int64_t>, "int list")
BIMART_SHORT_TYPE_NAME(std::vector<double>, "float list")
BIMART_SHORT_TYPE_NAME(std::vector<std::string>, "string list")

#undef BIMART_SHORT_TYPE_NAME

template <class T>
std::string type_name() {
  return TypeName<T>::get();
}

}  // namespace bimart
