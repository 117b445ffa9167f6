// Finding the project's shipped data (models/...): the same call works from the build
// tree, from an installed tree and with a user's own folder.
#pragma once

#include <string>
#include <vector>

namespace bimart {

// The folders searched, in order: $BIMART_DATA_DIR, <prefix>/share/bimart next to the
// installed core library, and the source tree this library was built from.
std::vector<std::string> data_dirs();

// `relative` (e.g. "models/bps/np_bps.npz") if it is an existing path as given, else the
// first folder of data_dirs() that holds it. Throws bimart::Error listing where it looked.
std::string find_data_file(const std::string& relative);

}  // namespace bimart
