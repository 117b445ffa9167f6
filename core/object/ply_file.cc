#include "core/object/ply_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "core/util/error.h"

namespace bimart {
namespace {

enum class Format { Ascii, BinaryLittle, BinaryBig };

struct Type {
  int size = 0;  // bytes; 0: unknown
  bool is_float = false;
  bool is_signed = false;
};

Type type_of(const std::string& name) {
  static const std::pair<const char*, Type> types[] = {
      {"char", {1, false, true}},     {"int8", {1, false, true}},    {"uchar", {1, false, false}},
      {"uint8", {1, false, false}},   {"short", {2, false, true}},   {"int16", {2, false, true}},
      {"ushort", {2, false, false}},  {"uint16", {2, false, false}}, {"int", {4, false, true}},
      {"int32", {4, false, true}},    {"uint", {4, false, false}},   {"uint32", {4, false, false}},
      {"float", {4, true, true}},     {"float32", {4, true, true}},  {"double", {8, true, true}},
      {"float64", {8, true, true}}};
  for (const auto& [n, t] : types)
    if (name == n) return t;
  return {};
}

struct Property {
  std::string name;
  Type type;        // the value's (a list's items)
  bool list = false;
  Type count_type;  // a list's count
};

struct Element {
  std::string name;
  std::int64_t count = 0;
  std::vector<Property> props;
  long line = 0;
};

std::vector<std::string> split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

// The body, value by value, in either encoding; every fault names where it is.
class Body {
 public:
  Body(const std::string& path, const std::string& bytes, std::size_t pos, long line, Format format)
      : path_(path), bytes_(bytes), pos_(pos), line_(line), format_(format) {}

  [[noreturn]] void fail(const std::string& why) const {
    if (format_ == Format::Ascii) throw Error(fmt::format("{}:{}: {}", path_, line_, why));
    throw Error(fmt::format("{}: byte {}: {}", path_, at_, why));
  }

  double value(const Type& t, const char* what) {
    return format_ == Format::Ascii ? ascii_value(t, what) : binary_value(t, what);
  }

  std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  double ascii_value(const Type& t, const char* what) {
    // Skip white space, counting lines.
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) {
      if (bytes_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ == bytes_.size()) fail(fmt::format("the file ends where a {} was expected", what));
    const std::size_t start = pos_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) {
      const unsigned char c = static_cast<unsigned char>(bytes_[pos_]);
      if (c < 32 || c > 126) fail("binary bytes in an ascii PLY body (damaged, or not ascii?)");
      ++pos_;
    }
    const std::string token = bytes_.substr(start, std::min<std::size_t>(pos_ - start, 64));
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || pos_ - start > 64)
      fail(fmt::format("{} '{}' is not a number", what, token));
    if (!std::isfinite(v)) fail(fmt::format("{} '{}' is not a finite number", what, token));
    if (!t.is_float && v != std::floor(v)) fail(fmt::format("{} '{}' is not a whole number", what, token));
    return v;
  }

  double binary_value(const Type& t, const char* what) {
    at_ = pos_;
    if (remaining() < static_cast<std::size_t>(t.size))
      fail(fmt::format("the file ends where a {} was expected (truncated)", what));
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, static_cast<std::size_t>(t.size));
    if (format_ == Format::BinaryBig) std::reverse(b, b + t.size);
    pos_ += static_cast<std::size_t>(t.size);
    if (t.is_float) {
      double v;
      if (t.size == 4) {
        float f;
        std::memcpy(&f, b, 4);
        v = f;
      } else {
        std::memcpy(&v, b, 8);
      }
      return v;
    }
    std::uint64_t u = 0;
    for (int i = t.size - 1; i >= 0; --i) u = (u << 8) | b[i];
    if (t.is_signed && (b[t.size - 1] & 0x80)) return static_cast<double>(u) - std::ldexp(1.0, 8 * t.size);
    return static_cast<double>(u);
  }

  const std::string& path_;
  const std::string& bytes_;
  std::size_t pos_;
  long line_;
  Format format_;
  std::size_t at_ = 0;  // where the last binary value starts
};

}  // namespace

PlyMesh read_ply_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open: " + std::strerror(errno));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto fail = [&](long line, const std::string& why) -> void {
    throw Error(line > 0 ? fmt::format("{}:{}: {}", path, line, why) : fmt::format("{}: {}", path, why));
  };
  if (bytes.empty()) fail(0, "the file is empty");

  // Header: text lines up to end_header.
  std::size_t pos = 0;
  long n = 0;
  auto next_line = [&](std::string& line) {
    if (pos >= bytes.size()) return false;
    const std::size_t eol = bytes.find('\n', pos);
    line = bytes.substr(pos, (eol == std::string::npos ? bytes.size() : eol) - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = eol == std::string::npos ? bytes.size() : eol + 1;
    ++n;
    return true;
  };
  std::string line;
  next_line(line);
  if (line != "ply") fail(1, "the first line must be 'ply'");
  std::vector<Element> elements;
  Format format = Format::Ascii;
  bool has_format = false, ended = false;
  while (next_line(line)) {
    for (unsigned char c : line)
      if (c == 0 || (c < 32 && c != '\t' && c != '\f' && c != '\v'))
        fail(n, "binary bytes in the PLY header (damaged, or not PLY?)");
    const auto t = split(line);
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      ended = true;
      break;
    }
    if (t[0] == "format") {
      if (t.size() < 2) fail(n, "'format' needs ascii, binary_little_endian or binary_big_endian");
      if (t[1] == "ascii") format = Format::Ascii;
      else if (t[1] == "binary_little_endian") format = Format::BinaryLittle;
      else if (t[1] == "binary_big_endian") format = Format::BinaryBig;
      else fail(n, "unknown PLY format '" + t[1].substr(0, 40) + "'");
      has_format = true;
    } else if (t[0] == "element") {
      if (t.size() < 3) fail(n, "'element' needs a name and a count");
      errno = 0;
      char* end = nullptr;
      const long long count = std::strtoll(t[2].c_str(), &end, 10);
      if (end == t[2].c_str() || *end != '\0' || errno == ERANGE || count < 0)
        fail(n, "element count '" + t[2].substr(0, 40) + "' is not a whole number of at least 0");
      elements.push_back({t[1], count, {}, n});
    } else if (t[0] == "property") {
      if (elements.empty()) fail(n, "'property' before any 'element'");
      Property p;
      p.list = t.size() >= 2 && t[1] == "list";
      if (p.list) {
        if (t.size() < 5) fail(n, "'property list' needs the count type, the item type and a name");
        p.count_type = type_of(t[2]);
        p.type = type_of(t[3]);
        p.name = t[4];
        if (p.count_type.size == 0 || p.type.size == 0) fail(n, "unknown property type in '" + line.substr(0, 60) + "'");
        if (p.count_type.is_float) fail(n, "a list's count type must be an integer type, not '" + t[2] + "'");
      } else {
        if (t.size() < 3) fail(n, "'property' needs a type and a name");
        p.type = type_of(t[1]);
        p.name = t[2];
        if (p.type.size == 0) fail(n, "unknown property type in '" + line.substr(0, 60) + "'");
      }
      elements.back().props.push_back(p);
    } else {
      fail(n, "unknown PLY header line '" + line.substr(0, 60) + "'");
    }
  }
  if (!ended) fail(n, "the header never ends ('end_header' missing)");
  if (!has_format) fail(n, "the header has no 'format' line");

  // Which element is which, and the bounds every count must keep.
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  for (const Element& e : elements) {
    double min_bytes = 0;  // per element: a number takes at least 2 bytes in ascii ("0 ")
    for (const Property& p : e.props) min_bytes += format == Format::Ascii ? 2 : (p.list ? p.count_type.size : p.type.size);
    if (static_cast<double>(e.count) * std::max(min_bytes, 1.0) > static_cast<double>(bytes.size() - pos))
      fail(n, fmt::format("the header declares {} {} elements, but the file has only {} bytes (truncated or damaged)",
                          e.count, e.name, bytes.size()));
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "face" && !face) face = &e;
  }
  if (!vertex || vertex->count == 0) fail(n, "the header declares no vertices");
  if (!face || face->count == 0) fail(n, "the header declares no faces");
  int xyz[3] = {-1, -1, -1};
  for (std::size_t k = 0; k < vertex->props.size(); ++k)
    for (int a = 0; a < 3; ++a)
      if (vertex->props[k].name == std::string(1, static_cast<char>('x' + a))) {
        if (vertex->props[k].list) fail(vertex->line, "the vertex property '" + vertex->props[k].name + "' is a list");
        xyz[a] = static_cast<int>(k);
      }
  for (int a = 0; a < 3; ++a)
    if (xyz[a] < 0) fail(vertex->line, fmt::format("the vertices have no '{}' property", static_cast<char>('x' + a)));
  int corners = -1;
  for (std::size_t k = 0; k < face->props.size(); ++k)
    if (face->props[k].list && (face->props[k].name == "vertex_indices" || face->props[k].name == "vertex_index"))
      corners = static_cast<int>(k);
  if (corners < 0) fail(face->line, "the faces have no list property 'vertex_indices' (or 'vertex_index')");
  if (face->props[static_cast<std::size_t>(corners)].type.is_float)
    fail(face->line, "face indices must be of an integer type");

  PlyMesh mesh;
  mesh.vertices.reserve(static_cast<std::size_t>(vertex->count));
  mesh.faces.reserve(static_cast<std::size_t>(face->count));
  Body body(path, bytes, pos, n + 1, format);
  for (const Element& e : elements) {
    for (std::int64_t i = 0; i < e.count; ++i) {
      std::array<double, 3> v{};
      for (std::size_t k = 0; k < e.props.size(); ++k) {
        const Property& p = e.props[k];
        if (!p.list) {
          const double x = body.value(p.type, &e == vertex ? "vertex coordinate" : "number");
          if (&e == vertex)
            for (int a = 0; a < 3; ++a)
              if (xyz[a] == static_cast<int>(k)) {
                if (!std::isfinite(x)) body.fail(fmt::format("vertex {} has a coordinate that is not finite", i));
                v[static_cast<std::size_t>(a)] = x;
              }
          continue;
        }
        const double count = body.value(p.count_type, "list count");
        const double item_bytes = format == Format::Ascii ? 1 : p.type.size;  // ascii: a digit at least
        if (count < 0 || count * item_bytes > static_cast<double>(body.remaining()) + 1)
          body.fail(fmt::format("a list of {} items does not fit in the rest of the file", count));
        const bool is_face = &e == face && static_cast<int>(k) == corners;
        if (is_face && count < 3) body.fail(fmt::format("face {} has {} corners (at least 3)", i, count));
        std::vector<std::int64_t> f;
        for (std::int64_t j = 0; j < static_cast<std::int64_t>(count); ++j) {
          const double id = body.value(p.type, is_face ? "face index" : "list item");
          if (!is_face) continue;
          if (id < 0 || id >= static_cast<double>(vertex->count))
            body.fail(fmt::format("face index {} is out of range [0, {})", id, vertex->count));
          f.push_back(static_cast<std::int64_t>(id));
        }
        if (is_face) mesh.faces.push_back(std::move(f));
      }
      if (&e == vertex) mesh.vertices.push_back(v);
    }
  }
  return mesh;
}

}  // namespace bimart
