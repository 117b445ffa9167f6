#include "core/util/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/util/error.h"
#include "core/util/interrupt.h"

namespace fs = std::filesystem;

namespace bimart {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), ec);
    if (ec)
      throw Error("cannot write " + path + ": cannot create folder " + target.parent_path().string() + ": " +
                  ec.message());
  }
  const fs::path tmp = target.string() + ".tmp-" + std::to_string(::getpid());
  const InterruptCleanup cleanup(tmp.string());
  try {
    {
      errno = 0;
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) throw Error("cannot write " + path + ": " + (errno ? std::strerror(errno) : "cannot create a file there"));
      write(out);
      out.flush();
      if (!out) throw Error("writing " + path + " failed" + (errno ? std::string(": ") + std::strerror(errno) : ""));
    }
    fs::rename(tmp, target, ec);
    if (ec) throw Error("cannot write " + path + ": " + ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace bimart
