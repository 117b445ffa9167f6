#include "core/util/data_path.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>

#include "core/util/error.h"
#include "core/util/text.h"

namespace fs = std::filesystem;

namespace bimart {

std::vector<std::string> data_dirs() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("BIMART_DATA_DIR"); env && *env) dirs.emplace_back(env);
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&data_dirs), &info) != 0 && info.dli_fname) {
    std::error_code ec;
    const fs::path lib = fs::weakly_canonical(info.dli_fname, ec);
    dirs.push_back((lib.parent_path().parent_path() / "share" / "bimart").string());
  }
#ifdef BIMART_SOURCE_DIR
  dirs.emplace_back(BIMART_SOURCE_DIR);
#endif
  return dirs;
}

std::string find_data_file(const std::string& relative) {
  std::error_code ec;
  if (fs::exists(relative, ec)) return relative;
  const auto dirs = data_dirs();
  for (const auto& d : dirs) {
    const fs::path p = fs::path(d) / relative;
    if (fs::exists(p, ec)) return p.string();
  }
  throw Error("cannot find " + relative + "; looked in the current folder and " + join(dirs, ", ") +
              " (set BIMART_DATA_DIR to the folder that holds models/)");
}

}  // namespace bimart
