// The message of the bimart::Error a callable throws, for tests of error messages.
#pragma once

#include <string>

#include "core/util/error.h"

namespace bimart::test {

// The message of the bimart::Error `f` throws, or "" when it throws none (other
// exceptions propagate and fail the test).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace bimart::test
