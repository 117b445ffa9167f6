// Writing a folder of outputs so that a failed run never leaves it half-written (the folder
// counterpart of core/util/atomic_file.h).
#pragma once

#include <functional>
#include <string>

namespace bimart {

// `write` fills a temporary sibling folder, which then replaces `dir`. An existing `dir` is
// replaced only with `replace` (else an error, before `write` runs); on any failure `dir` is
// untouched and the temporary folder removed.
void write_folder_atomically(const std::string& dir, const std::function<void(const std::string& tmp_dir)>& write,
                             bool replace);

}  // namespace bimart
