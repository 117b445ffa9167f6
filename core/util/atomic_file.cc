#include "core/util/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/util/error.h"

namespace fs = std::filesystem;

namespace bimart {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), ec);
    if (ec) throw Error("cannot create folder " + target.parent_path().string() + ": " + ec.message());
  }
  const fs::path tmp = target.string() + ".tmp-" + std::to_string(::getpid());
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) throw Error("cannot write " + tmp.string());
      write(out);
      out.flush();
      if (!out) throw Error("writing " + tmp.string() + " failed");
    }
    fs::rename(tmp, target, ec);
    if (ec) throw Error("cannot rename " + tmp.string() + " to " + path + ": " + ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace bimart
