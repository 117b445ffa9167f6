#include "core/object/mesh_file_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/object/ply_file.h"
#include "core/util/error.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

class Checker {
 public:
  Checker(std::string path, std::uintmax_t size) : path_(std::move(path)), size_(size) {}

  [[noreturn]] void fail(long line, const std::string& why) const {
    throw Error(line > 0 ? fmt::format("{}:{}: {}", path_, line, why) : fmt::format("{}: {}", path_, why));
  }

  // A text line must be text: binary bytes mean the wrong format or a damaged file.
  void text_only(const std::string& s, long line, const char* format) const {
    for (unsigned char c : s)
      if (c == 0 || (c < 32 && c != '\t' && c != '\r' && c != '\f' && c != '\v'))
        fail(line, fmt::format("binary bytes in a text {} file (damaged, or not {}?)", format, format));
  }

  double number(const std::string& token, long line, const char* what) const {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') fail(line, fmt::format("{} '{}' is not a number", what, token));
    if (!std::isfinite(v)) fail(line, fmt::format("{} '{}' is not a finite number", what, token));
    return v;
  }

  long integer(const std::string& token, long line, const char* what) const {
    errno = 0;
    char* end = nullptr;
    const long v = std::strtol(token.c_str(), &end, 10);
    if (end == token.c_str() || *end != '\0' || errno == ERANGE)
      fail(line, fmt::format("{} '{}' is not a whole number", what, token));
    return v;
  }

  // A header's element count: no more than the file could hold at `min_bytes` each.
  void count_fits(long line, const char* what, long count, double min_bytes) const {
    if (count < 0) fail(line, fmt::format("the header declares {} {}", count, what));
    if (static_cast<double>(count) * min_bytes > static_cast<double>(size_))
      fail(line, fmt::format("the header declares {} {}, but the file has only {} bytes (truncated or damaged)", count,
                             what, size_));
  }

  const std::string& path() const { return path_; }
  std::uintmax_t size() const { return size_; }

 private:
  std::string path_;
  std::uintmax_t size_;
};

std::vector<std::string> tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

void check_obj(const Checker& c, std::istream& in) {
  long vertices = 0, faces = 0, n = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    c.text_only(line, n, "OBJ");
    const auto t = tokens(line);
    if (t.empty() || t[0][0] == '#') continue;
    if (t[0] == "v") {
      if (t.size() < 4) c.fail(n, "a vertex ('v') needs 3 coordinates");
      for (int k = 1; k <= 3; ++k) c.number(t[static_cast<size_t>(k)], n, "vertex coordinate");
      ++vertices;
    } else if (t[0] == "f") {
      if (t.size() < 4) c.fail(n, fmt::format("a face ('f') needs at least 3 corners, this one has {}", t.size() - 1));
      for (size_t k = 1; k < t.size(); ++k) {
        const std::string id = t[k].substr(0, t[k].find('/'));
        const long i = c.integer(id, n, "face index");
        if (i == 0) c.fail(n, "face index 0: OBJ indices start at 1 (or count back from -1)");
        if (i > vertices || -i > vertices)
          c.fail(n, fmt::format("face index {} refers to vertex {}, but only {} vertices come before it", i,
                                i > 0 ? i : vertices + i + 1, vertices));
      }
      ++faces;
    }
  }
  if (n == 0) c.fail(0, "the file is empty");
  if (vertices == 0) c.fail(0, "no vertices ('v' lines): not an OBJ mesh");
  if (faces == 0) c.fail(0, fmt::format("{} vertices but no faces ('f' lines): a point cloud is no mesh", vertices));
}

// Next line that is not blank or a comment, split; false at the end.
bool next_tokens(std::istream& in, long& n, std::vector<std::string>& t, const Checker& c, const char* format) {
  for (std::string line; std::getline(in, line);) {
    ++n;
    c.text_only(line, n, format);
    const auto h = line.find('#');
    t = tokens(h == std::string::npos ? line : line.substr(0, h));
    if (!t.empty()) return true;
  }
  return false;
}

void check_off(const Checker& c, std::istream& in) {
  long n = 0;
  std::vector<std::string> t;
  if (!next_tokens(in, n, t, c, "OFF")) c.fail(0, "the file is empty");
  const std::string kind = t[0];
  if (kind.size() < 3 || kind.compare(kind.size() - 3, 3, "OFF") != 0)
    c.fail(n, "the first line must be 'OFF' (got '" + kind.substr(0, 40) + "')");
  const bool plain = kind == "OFF" && (t.size() < 2 || t[1] != "BINARY");
  t.erase(t.begin());
  if (t.empty() && !next_tokens(in, n, t, c, "OFF")) c.fail(n, "the header lacks the vertex and face counts");
  if (!plain) return;  // COFF, NOFF, binary OFF: counts are checked by CGAL, not here
  if (t.size() < 2) c.fail(n, "the header needs the counts: vertices faces [edges]");
  const long nv = c.integer(t[0], n, "vertex count"), nf = c.integer(t[1], n, "face count");
  c.count_fits(n, "vertices", nv, 6);  // "0 0 0\n"
  c.count_fits(n, "faces", nf, 8);     // "3 0 1 2\n"
  if (nv == 0) c.fail(n, "the header declares no vertices");
  if (nf == 0) c.fail(n, "the header declares no faces");
  for (long v = 0; v < nv; ++v) {
    if (!next_tokens(in, n, t, c, "OFF")) c.fail(n, fmt::format("ends after {} of {} vertices", v, nv));
    if (t.size() < 3) c.fail(n, "a vertex needs 3 coordinates");
    for (int k = 0; k < 3; ++k) c.number(t[static_cast<size_t>(k)], n, "vertex coordinate");
  }
  for (long f = 0; f < nf; ++f) {
    if (!next_tokens(in, n, t, c, "OFF")) c.fail(n, fmt::format("ends after {} of {} faces", f, nf));
    const long k = c.integer(t[0], n, "corner count");
    if (k < 3) c.fail(n, fmt::format("a face needs at least 3 corners, this one has {}", k));
    if (static_cast<long>(t.size()) < k + 1) c.fail(n, fmt::format("the face lists {} of {} corners", t.size() - 1, k));
    for (long i = 1; i <= k; ++i) {
      const long id = c.integer(t[static_cast<size_t>(i)], n, "face index");
      if (id < 0 || id >= nv) c.fail(n, fmt::format("face index {} is out of range [0, {})", id, nv));
    }
  }
}

void check_stl(const Checker& c, std::istream& in) {
  if (c.size() == 0) c.fail(0, "the file is empty");
  char head[84] = {};
  in.read(head, sizeof head);
  const std::streamsize got = in.gcount();
  std::uint32_t count = 0;
  if (got == 84) std::memcpy(&count, head + 80, 4);
  const bool binary_size = got == 84 && 84 + 50 * static_cast<std::uintmax_t>(count) == c.size();
  if (std::strncmp(head, "solid", 5) != 0 || binary_size) {
    // Binary: 80-byte header, a count, 50 bytes per triangle.
    if (got < 84) c.fail(0, fmt::format("{} bytes: too short for a binary STL (84-byte header)", c.size()));
    if (!binary_size)
      c.fail(0, fmt::format("the header declares {} triangles ({} bytes), but the file has {} bytes", count,
                            84 + 50 * static_cast<std::uintmax_t>(count), c.size()));
    if (count == 0) c.fail(0, "the file holds no triangles");
    for (std::uint32_t f = 0; f < count; ++f) {
      char rec[50];
      in.read(rec, sizeof rec);
      float xyz[12];
      std::memcpy(xyz, rec, sizeof xyz);
      for (int k = 3; k < 12; ++k)
        if (!std::isfinite(xyz[k])) c.fail(0, fmt::format("triangle {} has a coordinate that is not finite", f));
    }
    return;
  }
  in.clear();
  in.seekg(0);
  long n = 0, facets = 0;
  std::vector<std::string> t;
  while (next_tokens(in, n, t, c, "STL")) {
    if (t[0] == "vertex") {
      if (t.size() < 4) c.fail(n, "a vertex needs 3 coordinates");
      for (int k = 1; k <= 3; ++k) c.number(t[static_cast<size_t>(k)], n, "vertex coordinate");
    } else if (t[0] == "facet") {
      ++facets;
    }
  }
  if (facets == 0) c.fail(0, "no facets: an STL without triangles");
}

}  // namespace

void check_mesh_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error(path + ": mesh file not found");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(path + ": cannot read: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open: " + std::strerror(errno));
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  const Checker c(path, size);
  if (size == 0) c.fail(0, "the file is empty");
  if (ext == ".obj") check_obj(c, in);
  else if (ext == ".off") check_off(c, in);
  else if (ext == ".ply") read_ply_file(path);  // the reader itself checks (core/object/ply_file.h)
  else if (ext == ".stl") check_stl(c, in);
  else c.fail(0, "unknown mesh format '" + ext + "' (supported: .obj, .ply, .off, .stl)");
}

}  // namespace bimart
