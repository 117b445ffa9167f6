#include "core/io/npz.h"

#include <fmt/format.h>
#include <zip.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>

#include "core/util/atomic_file.h"

namespace bimart {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;
constexpr size_t kHeaderAlign = 64;  // numpy >= 1.15 pads the header to 64 bytes
constexpr int64_t kMaxElements = int64_t{1} << 48;
constexpr zip_uint64_t kMaxInflation = 1032;  // deflate's largest expansion ratio

// Bytes per element of a supported dtype code; 0 for an unknown one.
int dtype_size(const std::string& d) {
  if (d == "f8" || d == "i8" || d == "u8") return 8;
  if (d == "f4" || d == "i4" || d == "u4") return 4;
  if (d == "f2") return 2;  // read as tensors only (npz_tensor.h)
  if (d == "i1" || d == "u1" || d == "b1") return 1;
  // At most 7 digits: std::stol would throw on a longer count (found by fuzzing).
  if (d.size() >= 2 && d.size() <= 8 && d[0] == 'U' && std::all_of(d.begin() + 1, d.end(), ::isdigit)) {
    const long n = std::stol(d.substr(1));
    return n > 0 && n < (1 << 20) ? static_cast<int>(4 * n) : 0;
  }
  return 0;
}

const char* kSupported = "f2, f4, f8, i1, i4, i8, u1, u4, u8, b1, U<n>";

// UTF-8 <-> UCS-4 for the "U<n>" dtype. Invalid UTF-8 bytes become U+FFFD.
std::vector<uint32_t> utf8_to_ucs4(const std::string& s) {
  std::vector<uint32_t> out;
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    int extra = c < 0x80 ? 0 : (c >> 5) == 0x6 ? 1 : (c >> 4) == 0xE ? 2 : (c >> 3) == 0x1E ? 3 : -1;
    if (extra < 0 || i + extra >= s.size()) {
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    uint32_t cp = extra == 0 ? c : c & (0x3F >> extra);
    bool ok = true;
    for (int k = 1; k <= extra; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if ((b >> 6) != 0x2) ok = false;
      cp = (cp << 6) | (b & 0x3F);
    }
    out.push_back(ok ? cp : 0xFFFD);
    i += ok ? extra + 1 : 1;
  }
  return out;
}

void append_utf8(std::string& out, uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    if (cp > 0x10FFFF) cp = 0xFFFD;
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// A cursor over the header, a Python dict literal such as
// {'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }
class HeaderParser {
 public:
  HeaderParser(std::string text, std::string what) : s_(std::move(text)), what_(std::move(what)) {}

  void parse(std::string* descr, bool* fortran, std::vector<int64_t>* shape) {
    bool has_descr = false, has_fortran = false, has_shape = false;
    expect('{');
    while (true) {
      skip_space();
      if (peek() == '}') break;
      const std::string key = quoted();
      skip_space();
      expect(':');
      skip_space();
      if (key == "descr") {
        if (peek() == '[') fail("structured dtypes are not supported (descr is a list)");
        *descr = quoted();
        has_descr = true;
      } else if (key == "fortran_order") {
        *fortran = boolean();
        has_fortran = true;
      } else if (key == "shape") {
        *shape = tuple();
        has_shape = true;
      } else {
        fail("unexpected key '" + key + "'");
      }
      skip_space();
      if (peek() == ',') ++i_;
    }
    if (!has_descr || !has_fortran || !has_shape)
      fail("the header lacks one of 'descr', 'fortran_order', 'shape'");
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(what_ + ": bad .npy header (" + why + "): " + s_.substr(0, 120));
  }
  char peek() const {
    if (i_ >= s_.size()) fail("ends early");
    return s_[i_];
  }
  void skip_space() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  void expect(char c) {
    skip_space();
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++i_;
  }
  std::string quoted() {
    const char q = peek();
    if (q != '\'' && q != '"') fail("expected a quoted string");
    const size_t end = s_.find(q, i_ + 1);
    if (end == std::string::npos) fail("unterminated string");
    std::string out = s_.substr(i_ + 1, end - i_ - 1);
    i_ = end + 1;
    return out;
  }
  bool boolean() {
    if (s_.compare(i_, 4, "True") == 0) {
      i_ += 4;
      return true;
    }
    if (s_.compare(i_, 5, "False") == 0) {
      i_ += 5;
      return false;
    }
    fail("expected True or False");
  }
  std::vector<int64_t> tuple() {
    std::vector<int64_t> dims;
    expect('(');
    while (true) {
      skip_space();
      if (peek() == ')') {
        ++i_;
        return dims;
      }
      if (!std::isdigit(static_cast<unsigned char>(peek()))) fail("bad shape");
      int64_t v = 0;
      while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) {
        v = v * 10 + (s_[i_++] - '0');
        if (v > kMaxElements) fail("shape too large");
      }
      if (i_ < s_.size() && s_[i_] == 'L') ++i_;  // Python 2 long
      dims.push_back(v);
      skip_space();
      if (peek() == ',') ++i_;
    }
  }

  std::string s_;
  std::string what_;
  size_t i_ = 0;
};

constexpr time_t kFixedMemberTime = 315576000;  // 1980-01-01 12:00 UTC

std::string zip_message(int code) {
  zip_error_t err;
  zip_error_init_with_code(&err, code);
  std::string msg = zip_error_strerror(&err);
  zip_error_fini(&err);
  return msg;
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open '" + path + "': " + std::strerror(errno));
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

// ---- NpyArray ---------------------------------------------------------------------------

int64_t NpyArray::num_elements() const {
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  return n;
}

int NpyArray::item_size() const {
  const int s = dtype_size(dtype);
  if (s == 0) throw Error("unsupported npy dtype '" + dtype + "' (supported: " + kSupported + ")");
  return s;
}

bool NpyArray::is_numeric() const { return dtype_size(dtype) != 0 && dtype[0] != 'U'; }

std::string NpyArray::shape_str() const {
  std::string s = "(";
  for (size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

void NpyArray::check(const std::string& what) const {
  if (dtype_size(dtype) == 0)
    throw Error(what + ": unsupported dtype '" + dtype + "' (supported: " + kSupported + ")");
  int64_t n = 1;
  for (int64_t d : shape) {
    if (d < 0 || d > kMaxElements || (d > 0 && n > kMaxElements / d))
      throw Error(what + ": bad shape " + shape_str());
    n *= d;
  }
  if (static_cast<uint64_t>(n) * item_size() != data.size())
    throw Error(what + ": " + std::to_string(data.size()) + " data bytes, but shape " +
                shape_str() + " of " + dtype + " needs " + std::to_string(n * item_size()));
}

NpyArray make_npy_strings(const std::vector<std::string>& values, std::vector<int64_t> shape) {
  std::vector<std::vector<uint32_t>> cps;
  size_t width = 1;  // numpy's minimum is U1
  for (const auto& v : values) {
    cps.push_back(utf8_to_ucs4(v));
    width = std::max(width, cps.back().size());
  }
  NpyArray a{"U" + std::to_string(width), std::move(shape), {}};
  if (static_cast<size_t>(a.num_elements()) != values.size())
    throw Error("make_npy_strings: " + std::to_string(values.size()) +
                " strings do not fill shape " + a.shape_str());
  a.data.assign(values.size() * width * 4, 0);
  for (size_t i = 0; i < cps.size(); ++i)
    for (size_t k = 0; k < cps[i].size(); ++k)
      for (int b = 0; b < 4; ++b) a.data[(i * width + k) * 4 + b] = (cps[i][k] >> (8 * b)) & 0xFF;
  return a;
}

namespace detail {
void throw_conversion(const std::string& what, const std::string& dtype, double value,
                      const char* target) {
  std::ostringstream os;
  os.precision(17);
  os << what << ": value " << value << " (dtype " << dtype << ") is not " << target
     << " for an integer type";
  throw Error(os.str());
}
void throw_not_numeric(const std::string& what, const std::string& dtype) {
  throw Error(what + ": expected a numeric array, got dtype '" + dtype + "'");
}
}  // namespace detail

Eigen::MatrixXd to_eigen(const NpyArray& a, const std::string& what) {
  if (a.shape.size() > 2)
    throw Error(what + ": expected at most 2 dimensions, got shape " + a.shape_str());
  const Eigen::Index rows = a.shape.empty() ? 1 : a.shape[0];
  const Eigen::Index cols = a.shape.size() < 2 ? 1 : a.shape[1];
  return to_eigen(a, rows, cols, what);
}

Eigen::MatrixXd to_eigen(const NpyArray& a, Eigen::Index rows, Eigen::Index cols,
                         const std::string& what) {
  const std::vector<double> v = as_vector<double>(a, what);
  if (static_cast<Eigen::Index>(v.size()) != rows * cols)
    throw Error(what + ": shape " + a.shape_str() + " does not fit a " + std::to_string(rows) +
                " x " + std::to_string(cols) + " matrix");
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = v[r * cols + c];
  return m;
}

std::vector<std::string> as_strings(const NpyArray& a, const std::string& what) {
  a.check(what);
  if (a.dtype[0] != 'U') throw Error(what + ": expected a string array, got dtype '" + a.dtype + "'");
  const size_t width = a.item_size() / 4;
  std::vector<std::string> out(static_cast<size_t>(a.num_elements()));
  for (size_t i = 0; i < out.size(); ++i) {
    for (size_t k = 0; k < width; ++k) {
      uint32_t cp = 0;
      for (int b = 0; b < 4; ++b) cp |= uint32_t{a.data[(i * width + k) * 4 + b]} << (8 * b);
      if (cp == 0) break;
      append_utf8(out[i], cp);
    }
  }
  return out;
}

// ---- .npy -------------------------------------------------------------------------------

std::vector<uint8_t> serialize_npy(const NpyArray& a) {
  a.check("npy array");
  const char order = a.item_size() == 1 && a.dtype[0] != 'U' ? '|' : '<';
  std::string header = "{'descr': '" + std::string(1, order) + a.dtype +
                       "', 'fortran_order': False, 'shape': " + a.shape_str() + ", }";
  // Magic (6) + version (2) + length (2) + header + '\n', padded with spaces to 64 bytes.
  const size_t unpadded = kMagicSize + 4 + header.size() + 1;
  header.append((kHeaderAlign - unpadded % kHeaderAlign) % kHeaderAlign, ' ');
  header += '\n';
  if (header.size() > 65535) throw Error("npy header too long for shape " + a.shape_str());
  std::vector<uint8_t> out(kMagic, kMagic + kMagicSize);
  out.push_back(1);
  out.push_back(0);
  out.push_back(header.size() & 0xFF);
  out.push_back(header.size() >> 8);
  out.insert(out.end(), header.begin(), header.end());
  out.insert(out.end(), a.data.begin(), a.data.end());
  return out;
}

NpyArray parse_npy(const uint8_t* bytes, size_t size, const std::string& what) {
  if (size < kMagicSize + 4 || std::memcmp(bytes, kMagic, kMagicSize) != 0)
    throw Error(what + ": not a .npy array (bad magic bytes)");
  const int major = bytes[6];
  size_t header_len = 0, pos = 0;
  if (major == 1) {
    header_len = bytes[8] | (size_t{bytes[9]} << 8);
    pos = 10;
  } else if (major == 2 || major == 3) {
    if (size < 12) throw Error(what + ": truncated .npy header");
    header_len = bytes[8] | (size_t{bytes[9]} << 8) | (size_t{bytes[10]} << 16) |
                 (size_t{bytes[11]} << 24);
    pos = 12;
  } else {
    throw Error(what + ": unsupported .npy format version " + std::to_string(major));
  }
  if (pos + header_len > size) throw Error(what + ": truncated .npy header");
  const std::string header(reinterpret_cast<const char*>(bytes + pos), header_len);
  pos += header_len;

  std::string descr;
  bool fortran = false;
  NpyArray a;
  HeaderParser(header, what).parse(&descr, &fortran, &a.shape);
  if (fortran)
    throw Error(what + ": Fortran-order arrays are not supported; save a C-order copy "
                       "(numpy.ascontiguousarray)");
  if (!descr.empty() && descr[0] == '>' && descr.size() > 1 && dtype_size(descr.substr(1)) > 1)
    throw Error(what + ": big-endian dtype '" + descr + "' is not supported; convert with "
                       "arr.astype(arr.dtype.newbyteorder('<'))");
  if (!descr.empty() && (descr[0] == '<' || descr[0] == '|' || descr[0] == '=' || descr[0] == '>'))
    descr = descr.substr(1);
  a.dtype = descr;
  if (dtype_size(a.dtype) == 0)
    throw Error(what + ": unsupported dtype '" + descr + "' (supported: " + kSupported + ")");
  a.data.assign(bytes + pos, bytes + size);
  a.check(what);
  return a;
}

NpyArray read_npy(const std::string& path) {
  const std::vector<uint8_t> bytes = read_bytes(path);
  return parse_npy(bytes.data(), bytes.size(), path);
}

void write_npy(const std::string& path, const NpyArray& a) {
  const std::vector<uint8_t> bytes = serialize_npy(a);
  write_file_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

// ---- .npz -------------------------------------------------------------------------------

NpzFile NpzFile::read(const std::string& path) {
  int code = 0;
  zip_t* za = zip_open(path.c_str(), ZIP_RDONLY, &code);
  if (!za) {
    const std::string why = code == ZIP_ER_NOENT ? "no such file"
                            : code == ZIP_ER_NOZIP ? "not a .npz (zip) archive"
                                                   : zip_message(code);
    throw Error("cannot read '" + path + "': " + why);
  }
  std::unique_ptr<zip_t, decltype(&zip_discard)> archive(za, &zip_discard);

  NpzFile npz;
  npz.path_ = path;
  std::error_code size_error;
  const zip_uint64_t archive_size = std::filesystem::file_size(path, size_error);
  const zip_int64_t n = zip_get_num_entries(za, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    zip_stat_t st;
    if (zip_stat_index(za, i, 0, &st) != 0 || !(st.valid & ZIP_STAT_NAME) ||
        !(st.valid & ZIP_STAT_SIZE))
      throw Error(path + ": cannot read member " + std::to_string(i) + ": " +
                  zip_strerror(za));
    const std::string name = st.name;
    if (name.size() < 4 || name.compare(name.size() - 4, 4, ".npy") != 0) continue;
    const std::string key = name.substr(0, name.size() - 4);
    const std::string what = npz.where(key);
    std::unique_ptr<zip_file_t, decltype(&zip_fclose)> f(zip_fopen_index(za, i, 0), &zip_fclose);
    if (!f) throw Error(what + ": cannot open: " + zip_strerror(za));
    // The sizes in the archive's directory are claims: a damaged 1 KB file may declare a
    // 4 GB member. Bound them by what the file's bytes can hold (deflate expands at most
    // 1032:1), and grow the buffer as data arrives rather than trusting the claim.
    const zip_uint64_t comp = (st.valid & ZIP_STAT_COMP_SIZE) ? st.comp_size : archive_size;
    if (comp > archive_size || st.size > kMaxInflation * comp + 1024)
      throw Error(fmt::format("{}: the archive declares {} bytes ({} compressed) for this member, more than its {} "
                              "bytes can hold; the file is damaged",
                              what, st.size, comp, archive_size));
    std::vector<uint8_t> bytes;
    zip_uint64_t got = 0;
    while (got < st.size) {
      const zip_uint64_t chunk = std::min<zip_uint64_t>(st.size - got, zip_uint64_t{1} << 24);
      bytes.resize(static_cast<size_t>(got + chunk));
      const zip_int64_t r = zip_fread(f.get(), bytes.data() + got, chunk);
      if (r < 0) throw Error(what + ": corrupt data: " + zip_file_strerror(f.get()));
      if (r == 0) break;
      got += static_cast<zip_uint64_t>(r);
    }
    bytes.resize(static_cast<size_t>(got));
    if (got != st.size) throw Error(what + ": truncated member");
    // libzip checks the CRC only when a read reaches the end of the member, which reading
    // exactly st.size bytes never does; numpy checks it, so do we.
    if (st.valid & ZIP_STAT_CRC) {
      const uLong crc = crc32_z(crc32_z(0L, Z_NULL, 0), bytes.data(), bytes.size());
      if (crc != st.crc)
        throw Error(fmt::format("{}: corrupt member (CRC-32 {:08x}, the archive says {:08x}); the file is damaged",
                                what, crc, st.crc));
    }
    npz.arrays_[key] = parse_npy(bytes.data(), bytes.size(), what);
  }
  return npz;
}

void NpzFile::write(const std::string& path, NpzCompression compression) const {
  if (arrays_.empty()) {
    // libzip writes nothing for an empty archive; numpy writes the 22-byte end record.
    write_file_atomically(path, [](std::ostream& out) {
      const char end_record[22] = {0x50, 0x4b, 0x05, 0x06};
      out.write(end_record, sizeof(end_record));
    });
    return;
  }
  // Serialised members must outlive zip_close(), which reads them.
  std::vector<std::vector<uint8_t>> members;
  members.reserve(arrays_.size());
  for (const auto& [key, array] : arrays_) members.push_back(serialize_npy(array));

  zip_error_t err;
  zip_error_init(&err);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &err);
  if (!buffer) throw Error("cannot write '" + path + "': " + zip_error_strerror(&err));
  std::unique_ptr<zip_source_t, decltype(&zip_source_free)> buffer_guard(buffer, &zip_source_free);
  zip_source_keep(buffer);  // zip_close() would free it otherwise; we read it afterwards
  zip_t* za = zip_open_from_source(buffer, ZIP_TRUNCATE, &err);
  if (!za) throw Error("cannot write '" + path + "': " + zip_error_strerror(&err));
  std::unique_ptr<zip_t, decltype(&zip_discard)> archive(za, &zip_discard);

  size_t m = 0;
  for (const auto& [key, array] : arrays_) {
    const std::vector<uint8_t>& bytes = members[m++];
    zip_source_t* src = zip_source_buffer(za, bytes.data(), bytes.size(), 0);
    const zip_int64_t idx = src ? zip_file_add(za, (key + ".npy").c_str(), src, ZIP_FL_ENC_UTF_8) : -1;
    if (idx < 0) {
      if (src) zip_source_free(src);
      throw Error(where(key) + ": cannot add to archive '" + path + "': " + zip_strerror(za));
    }
    // A fixed member time (1980-01-01 12:00, DOS time has no earlier date) instead of "now",
    // so the same arrays give byte-identical files (data synthesis promises that).
    if (zip_file_set_mtime(za, static_cast<zip_uint64_t>(idx), kFixedMemberTime, 0) != 0)
      throw Error(where(key) + ": cannot set the member time: " + zip_strerror(za));
    const zip_int32_t method = compression == NpzCompression::Deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE;
    if (zip_set_file_compression(za, idx, method, 0) != 0)
      throw Error(where(key) + ": cannot set compression: " + zip_strerror(za));
  }
  if (zip_close(za) != 0) throw Error("cannot write '" + path + "': " + zip_strerror(za));
  archive.release();  // closed

  // Copy the finished archive out of the memory buffer, then write it atomically.
  std::vector<uint8_t> bytes;
  if (zip_source_open(buffer) != 0 || zip_source_seek(buffer, 0, SEEK_END) != 0)
    throw Error("cannot write '" + path + "': cannot read the built archive");
  const zip_int64_t size = zip_source_tell(buffer);
  zip_source_seek(buffer, 0, SEEK_SET);
  bytes.resize(static_cast<size_t>(std::max<zip_int64_t>(size, 0)));
  const zip_int64_t got = size > 0 ? zip_source_read(buffer, bytes.data(), bytes.size()) : 0;
  zip_source_close(buffer);
  if (got != size) throw Error("cannot write '" + path + "': cannot read the built archive");
  write_file_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

const NpyArray& NpzFile::get(const std::string& key) const {
  auto it = arrays_.find(key);
  if (it == arrays_.end()) {
    std::string have;
    for (const auto& k : keys()) have += (have.empty() ? "" : ", ") + k;
    throw Error((path_.empty() ? std::string("npz") : path_) + ": no array '" + key +
                "' (it has: " + (have.empty() ? "nothing" : have) + ")");
  }
  return it->second;
}

const NpyArray& NpzFile::get(const std::string& key, const std::vector<int64_t>& shape) const {
  const NpyArray& a = get(key);
  bool ok = a.shape.size() == shape.size();
  for (size_t i = 0; ok && i < shape.size(); ++i) ok = shape[i] < 0 || shape[i] == a.shape[i];
  if (!ok) {
    std::string want = "(";
    for (size_t i = 0; i < shape.size(); ++i)
      want += (i ? ", " : "") + (shape[i] < 0 ? std::string("any") : std::to_string(shape[i]));
    want += shape.size() == 1 ? ",)" : ")";
    throw Error(where(key) + " has shape " + a.shape_str() + ", expected " + want);
  }
  return a;
}

void NpzFile::set(const std::string& key, NpyArray array) {
  if (key.empty()) throw Error("npz: empty array key");
  array.check(where(key));
  arrays_[key] = std::move(array);
}

std::vector<std::string> NpzFile::keys() const {
  std::vector<std::string> k;
  for (const auto& [key, a] : arrays_) k.push_back(key);
  return k;
}

std::string NpzFile::where(const std::string& key) const {
  return (path_.empty() ? std::string("npz") : path_) + ": array '" + key + "'";
}

}  // namespace bimart
