// Checking where a command will write before it starts working (DESIGN §8), so a folder
// that cannot be written fails at once with its name, not after minutes of work.
#pragma once

#include <string>

namespace bimart {

// `path` is a file to be written: not a folder, and its folder exists (created when
// missing) and takes a new file (probed by creating and removing one). Throws
// bimart::Error naming the path and the reason.
void check_output_file(const std::string& path);
// `dir` is a folder to write into: created when missing, and takes a new file.
void check_output_folder(const std::string& dir);

}  // namespace bimart
