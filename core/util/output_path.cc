#include "core/util/output_path.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/util/error.h"

namespace fs = std::filesystem;

namespace bimart {

namespace {

void probe_folder(const fs::path& dir, const std::string& target) {
  std::error_code ec;
  if (!dir.empty() && !fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) throw Error("cannot write " + target + ": cannot create folder " + dir.string() + ": " + ec.message());
  }
  if (!dir.empty() && !fs::is_directory(dir, ec))
    throw Error("cannot write " + target + ": " + dir.string() + " is not a folder");
  const fs::path probe = (dir.empty() ? fs::path(".") : dir) / (".bimart-write-check-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) {
    const int err = errno;
    throw Error("cannot write " + target + ": " + (dir.empty() ? std::string(".") : dir.string()) + ": " +
                std::strerror(err));
  }
  ::close(fd);
  fs::remove(probe, ec);
}

}  // namespace

void check_output_file(const std::string& path) {
  if (path.empty()) throw Error("an output path is empty");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error("cannot write " + path + ": it is a folder");
  probe_folder(fs::path(path).parent_path(), path);
}

void check_output_folder(const std::string& dir) {
  if (dir.empty()) throw Error("an output folder is empty");
  probe_folder(fs::path(dir), dir);
}

}  // namespace bimart
