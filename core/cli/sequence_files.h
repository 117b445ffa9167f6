// The sequence files a command works on: every *.npz below a folder, or those a data set's
// manifest lists under a split. Shared by `bimart eval` and `bimart refine`.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/io/sequence.h"
#include "core/object/object_cache.h"
#include "core/util/error.h"

namespace bimart::cli {

// Sorted *.npz below `folder`, or with `split` the paths under that key of
// folder/manifest.json. Throws bimart::Error when there are none or a listed file is missing.
std::vector<std::string> sequence_files(const std::string& folder, const std::string& split);

// An error met while working on one sequence file, prefixed by the file unless it names it.
Error in_sequence_file(const std::string& file, const Error& e);

// The object a sequence refers to, loaded once through `cache`. An error names the
// sequence file and its `object` as written, e.g. after the object folder was moved.
std::shared_ptr<const ObjectCache::Entry> sequence_object(ObjectCache& cache, const Sequence& s,
                                                          const std::string& file);

}  // namespace bimart::cli
