#include "core/util/atomic_folder.h"

#include <unistd.h>

#include <filesystem>

#include "core/util/error.h"

namespace fs = std::filesystem;

namespace bimart {

void write_folder_atomically(const std::string& dir, const std::function<void(const std::string&)>& write,
                             bool replace) {
  const fs::path target = fs::absolute(dir).lexically_normal();
  const fs::path clean = target.filename().empty() ? target.parent_path() : target;  // "out/" -> "out"
  std::error_code ec;
  const bool exists = fs::exists(clean, ec);
  if (exists && !replace) throw Error("cannot write " + dir + ": it exists");
  if (exists && !fs::is_directory(clean, ec)) throw Error("cannot write " + dir + ": it is a file, not a folder");
  fs::create_directories(clean.parent_path(), ec);
  if (ec) throw Error("cannot write " + dir + ": cannot create folder " + clean.parent_path().string() + ": " + ec.message());
  const std::string pid = std::to_string(::getpid());
  const fs::path tmp = clean.string() + ".tmp-" + pid, old = clean.string() + ".old-" + pid;
  fs::remove_all(tmp, ec);
  try {
    fs::create_directory(tmp, ec);
    if (ec) throw Error("cannot write " + dir + ": cannot create folder " + tmp.string() + ": " + ec.message());
    write(tmp.string());
    if (exists) {
      fs::rename(clean, old, ec);
      if (ec) throw Error("cannot replace " + dir + ": " + ec.message());
    }
    fs::rename(tmp, clean, ec);
    if (ec) {
      if (exists) fs::rename(old, clean);
      throw Error("cannot write " + dir + ": " + ec.message());
    }
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  if (exists) fs::remove_all(old, ec);
}

}  // namespace bimart
