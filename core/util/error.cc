#include "core/util/error.h"

namespace bimart {

std::string SourceLocation::str() const {
  if (file.empty()) return "";
  std::string s = file;
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

Error::Error(const std::string& message) : std::runtime_error(message), message_(message) {}

Error::Error(const SourceLocation& where, const std::string& message)
    : std::runtime_error(where.known() ? where.str() + ": " + message : message),
      where_(where),
      message_(message) {}

}  // namespace bimart
