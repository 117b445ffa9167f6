// The sequence files a command works on: every *.npz below a folder, or those a data set's
// manifest lists under a split. Shared by `bimart eval` and `bimart refine`.
#pragma once

#include <string>
#include <vector>

namespace bimart::cli {

// Sorted *.npz below `folder`, or with `split` the paths under that key of
// folder/manifest.json. Throws bimart::Error when there are none or a listed file is missing.
std::vector<std::string> sequence_files(const std::string& folder, const std::string& split);

}  // namespace bimart::cli
