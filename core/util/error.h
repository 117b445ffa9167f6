// Errors a user can cause end here: one exception type, with an optional place in a file.
#pragma once

#include <stdexcept>
#include <string>

namespace bimart {

// A position in a text file; line and column are 1-based, 0 when unknown.
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;

  bool known() const { return !file.empty(); }
  std::string str() const;  // "file:line:col" (parts that are unknown are left out)
};

// The error every user-facing failure throws. what() is the full message, prefixed by the
// location when there is one, e.g. "pipelines/smoke.yaml:12:7: unknown parameter 'frmes'".
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message);
  Error(const SourceLocation& where, const std::string& message);

  const SourceLocation& where() const { return where_; }
  const std::string& message() const { return message_; }

 private:
  SourceLocation where_;
  std::string message_;
};

}  // namespace bimart
