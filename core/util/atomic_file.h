// Writing outputs so that a failed run never leaves a half-written file: write to a
// temporary name in the same folder, then rename over the target.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace bimart {

// Creates missing parent folders. Throws bimart::Error naming the path on any failure;
// the target is then untouched and the temporary file removed.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace bimart
