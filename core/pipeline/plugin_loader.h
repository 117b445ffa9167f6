// Loads plug-in libraries into a registry. Checks, in order, that the library opens with
// all its symbols resolved, exports the bimart entry points, and was built with the same
// ABI version, compiler, C++ ABI and libtorch as this host; only then registers its stages.
// Every failure is a bimart::Error naming the library; nothing is registered from it.
#pragma once

#include <string>
#include <vector>

#include "core/pipeline/registry.h"

namespace bimart {

struct LoadedLibrary {
  std::string path;  // canonical path
  std::vector<std::string> stages;
};

class PluginLoader {
 public:
  explicit PluginLoader(Registry& registry) : registry_(registry) {}

  // The loader that fills Registry::global().
  static PluginLoader& global();

  // Loads one library; a library already loaded (same canonical path) is skipped.
  void load(const std::string& path);
  // Loads every *.so in `dir` (sorted by name); a missing directory is skipped.
  void load_directory(const std::string& dir);
  // Loads the built-in plug-ins (next to the core library: <libdir>/bimart/plugins) and
  // everything named in BIMART_PLUGIN_PATH (':'-separated files or directories).
  void load_startup();

  const std::vector<LoadedLibrary>& libraries() const { return libraries_; }

 private:
  Registry& registry_;
  std::vector<LoadedLibrary> libraries_;
};

// Directory of the built-in plug-ins, found relative to the core library itself, so the
// build tree and an installed tree work alike.
std::string builtin_plugin_dir();

}  // namespace bimart
