#include "core/cli/sequence_files.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/util/error.h"

namespace bimart::cli {

namespace fs = std::filesystem;

std::vector<std::string> sequence_files(const std::string& folder, const std::string& split) {
  if (!fs::is_directory(folder)) throw Error(folder + ": not a folder");
  std::vector<std::string> files;
  if (!split.empty()) {
    const fs::path manifest = fs::path(folder) / "manifest.json";
    if (!fs::exists(manifest)) throw Error(manifest.string() + ": missing (needed by --split " + split + ")");
    nlohmann::json j;
    try {
      std::ifstream in(manifest);
      in >> j;
    } catch (const std::exception& e) {
      throw Error(manifest.string() + ": not valid JSON: " + e.what());
    }
    if (!j.is_object() || !j.contains(split) || !j[split].is_array())
      throw Error(manifest.string() + ": no list \"" + split + "\"");
    for (const auto& p : j[split]) {
      if (!p.is_string()) throw Error(manifest.string() + ": \"" + split + "\" must list file paths");
      const fs::path f = fs::path(folder) / p.get<std::string>();
      if (!fs::exists(f)) throw Error(manifest.string() + ": listed file " + f.string() + " does not exist");
      files.push_back(f.string());
    }
  } else {
    for (const auto& e : fs::recursive_directory_iterator(folder))
      if (e.is_regular_file() && e.path().extension() == ".npz") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
  }
  if (files.empty()) throw Error(folder + ": no .npz sequence files" + (split.empty() ? "" : " in split " + split));
  return files;
}

Error in_sequence_file(const std::string& file, const Error& e) {
  const std::string m = e.what();
  if (m.compare(0, file.size(), file) == 0) return e;
  return Error(file + ": " + m);
}

std::shared_ptr<const ObjectCache::Entry> sequence_object(ObjectCache& cache, const Sequence& s,
                                                          const std::string& file) {
  const std::string path = resolve_object_path(s, file);
  try {
    return cache.get(path);
  } catch (const Error& e) {
    throw Error(file + ": its object '" + s.object + "' (" + path + "): " + e.what());
  }
}

}  // namespace bimart::cli
