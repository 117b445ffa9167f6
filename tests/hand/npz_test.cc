#include "core/io/npz.h"
#include "tests/error_of.h"

using bimart::test::error_of;

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zip.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

namespace bimart {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class NpzTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("bimart_npz_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::vector<uint8_t> file_bytes(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}
void write_bytes(const std::string& p, const std::vector<uint8_t>& b) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}
// One array of every supported dtype, and the shapes that are easy to get wrong.
NpzFile every_dtype() {
  NpzFile npz;
  npz.set("f8", make_npy(std::vector<double>{1.5, -2.25, 1e300, 0, 3, 4}, {2, 3}));
  npz.set("f4", make_npy(std::vector<float>{0.5f, -1.0f, 3.25f}));
  npz.set("i1", make_npy(std::vector<int8_t>{-128, 0, 127, 5}, {2, 2}));
  npz.set("u1", make_npy(std::vector<uint8_t>{0, 255}));
  npz.set("i4", make_npy(std::vector<int32_t>{-2147483647 - 1, 7}));
  npz.set("u4", make_npy(std::vector<uint32_t>{4294967295u, 1}));
  npz.set("i8", make_npy(std::vector<int64_t>{-(int64_t{1} << 62), 9, 8, 7, 6, 5, 4, 3}, {2, 2, 2}));
  npz.set("u8", make_npy(std::vector<uint64_t>{std::numeric_limits<uint64_t>::max()}));
  npz.set("b1", make_npy_scalar(true));
  npz.set("scalar_f8", make_npy_scalar(2.5));
  npz.set("empty", make_npy(std::vector<int32_t>{}, {0, 3}));
  npz.set("names", make_npy_strings({"wrist", "thumb", "h\xC3\xA9llo"}, {3}));
  return npz;
}

void expect_same(const NpzFile& a, const NpzFile& b) {
  ASSERT_EQ(a.keys(), b.keys());
  for (const auto& k : a.keys()) {
    SCOPED_TRACE(k);
    EXPECT_EQ(a.get(k).dtype, b.get(k).dtype);
    EXPECT_EQ(a.get(k).shape, b.get(k).shape);
    EXPECT_EQ(a.get(k).data, b.get(k).data);
  }
}

int member_method(const std::string& path, const std::string& member) {
  int err = 0;
  zip_t* za = zip_open(path.c_str(), ZIP_RDONLY, &err);
  if (!za) return -100;
  zip_stat_t st;
  const int r = zip_stat(za, member.c_str(), 0, &st);
  zip_discard(za);
  return r == 0 ? st.comp_method : -1;
}

TEST_F(NpzTest, RoundTripsEveryDtypeCompressedAndStored) {
  const NpzFile npz = every_dtype();
  npz.write(path("deflate.npz"), NpzCompression::Deflate);
  npz.write(path("store.npz"), NpzCompression::Store);
  const NpzFile deflated = NpzFile::read(path("deflate.npz"));
  const NpzFile stored = NpzFile::read(path("store.npz"));
  expect_same(npz, deflated);
  expect_same(npz, stored);
  EXPECT_EQ(deflated.path(), path("deflate.npz"));
  EXPECT_EQ(member_method(path("deflate.npz"), "f8.npy"), ZIP_CM_DEFLATE);
  EXPECT_EQ(member_method(path("store.npz"), "f8.npy"), ZIP_CM_STORE);
  // Values, not just bytes.
  EXPECT_EQ(stored.vector<double>("f8"), (std::vector<double>{1.5, -2.25, 1e300, 0, 3, 4}));
  EXPECT_EQ(stored.vector<int64_t>("u4"), (std::vector<int64_t>{4294967295LL, 1}));
  EXPECT_EQ(as_strings(stored.get("names")),
            (std::vector<std::string>{"wrist", "thumb", "h\xC3\xA9llo"}));
  EXPECT_EQ(stored.get("names").dtype, "U5");
  EXPECT_TRUE(stored.get("scalar_f8").shape.empty());
  EXPECT_EQ(stored.vector<double>("scalar_f8"), std::vector<double>{2.5});
  EXPECT_EQ(stored.vector<int>("b1"), std::vector<int>{1});
  EXPECT_EQ(stored.get("empty").shape, (std::vector<int64_t>{0, 3}));
}

TEST_F(NpzTest, DeflateShrinksRepetitiveData) {
  NpzFile npz;
  npz.set("zeros", make_npy(std::vector<double>(100000, 0.0)));
  npz.write(path("d.npz"), NpzCompression::Deflate);
  npz.write(path("s.npz"), NpzCompression::Store);
  EXPECT_GT(fs::file_size(path("s.npz")), 800000u);
  EXPECT_LT(fs::file_size(path("d.npz")), 10000u);
}

// The same arrays give the same bytes: members carry a fixed time, not the clock's.
TEST_F(NpzTest, MembersCarryAFixedTimeSoFilesAreReproducible) {
  const NpzFile npz = every_dtype();
  npz.write(path("a.npz"), NpzCompression::Deflate);
  int err = 0;
  zip_t* za = zip_open(path("a.npz").c_str(), ZIP_RDONLY, &err);
  ASSERT_NE(za, nullptr);
  zip_stat_t st;
  ASSERT_EQ(zip_stat(za, "f8.npy", 0, &st), 0);
  zip_discard(za);
  ASSERT_TRUE(st.valid & ZIP_STAT_MTIME);
  // 1980-01-01 12:00 in DOS time, read back through the local time zone: within a day.
  EXPECT_LT(std::abs(static_cast<double>(st.mtime) - 315576000.0), 86400.0);
  std::ifstream a(path("a.npz"), std::ios::binary);
  const std::string first((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
  npz.write(path("b.npz"), NpzCompression::Deflate);
  std::ifstream b(path("b.npz"), std::ios::binary);
  EXPECT_EQ(first, std::string((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>()));
}

// Headers byte for byte as numpy 1.24 writes them (np.save on the same arrays).
TEST(NpyTest, SerializesHeadersAsNumpyDoes) {
  const auto f8 = serialize_npy(make_npy(std::vector<double>(6, 0.0), {2, 3}));
  ASSERT_EQ(f8.size(), 176u);  // 128-byte header + 48 data bytes
  const std::string header(f8.begin() + 10, f8.begin() + 128);
  const std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }";
  EXPECT_EQ(header, dict + std::string(118 - dict.size() - 1, ' ') + "\n");
  EXPECT_EQ(f8[8] | (f8[9] << 8), 118);
  EXPECT_EQ(serialize_npy(make_npy_scalar(1.5f)).size(), 132u);
  EXPECT_EQ(serialize_npy(make_npy_strings({"ab", "cde"}, {2})).size(), 152u);
  const auto b1 = serialize_npy(make_npy_scalar(false));
  EXPECT_EQ(std::string(b1.begin() + 10, b1.begin() + 23), "{'descr': '|b");
}

std::vector<uint8_t> npy_with_header(const std::string& dict, const std::vector<uint8_t>& data,
                                     int version = 1) {
  std::vector<uint8_t> out = {0x93, 'N', 'U', 'M', 'P', 'Y', static_cast<uint8_t>(version), 0};
  const size_t n = dict.size();
  out.push_back(n & 0xFF);
  out.push_back((n >> 8) & 0xFF);
  if (version >= 2) {
    out.push_back((n >> 16) & 0xFF);
    out.push_back((n >> 24) & 0xFF);
  }
  out.insert(out.end(), dict.begin(), dict.end());
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

TEST(NpyTest, ParsesVersion2AndPython2Headers) {
  const std::vector<uint8_t> data = {1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0};
  const auto bytes =
      npy_with_header("{'shape': (3L,), 'fortran_order': False, 'descr': '<u4'}\n", data, 2);
  const NpyArray a = parse_npy(bytes.data(), bytes.size(), "t");
  EXPECT_EQ(a.dtype, "u4");
  EXPECT_EQ(as_vector<int>(a), (std::vector<int>{1, 2, 3}));
}

TEST(NpyTest, RefusesAnEnormousStringLengthWithAnError) {
  // Found by fuzzing: a U<n> count past long's range made std::stol throw out_of_range.
  const std::vector<uint8_t> data(48, 0);
  const auto bytes =
      npy_with_header("{'descr': '<U99999999999999999999999', 'fortran_order': False, 'shape': (1,), }\n", data);
  EXPECT_THROW(parse_npy(bytes.data(), bytes.size(), "x.npy"), Error);
}

TEST(NpyTest, RefusesFortranOrderBigEndianAndTruncation) {
  const std::vector<uint8_t> data(48, 0);
  auto parse = [](const std::vector<uint8_t>& b) { parse_npy(b.data(), b.size(), "x.npy"); };
  EXPECT_THAT(error_of([&] {
                parse(npy_with_header("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }\n", data));
              }),
              HasSubstr("x.npy: Fortran-order arrays are not supported"));
  EXPECT_THAT(error_of([&] {
                parse(npy_with_header("{'descr': '>f8', 'fortran_order': False, 'shape': (2, 3), }\n", data));
              }),
              HasSubstr("big-endian"));
  EXPECT_THAT(error_of([&] {
                parse(npy_with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 4), }\n", data));
              }),
              HasSubstr("48 data bytes, but shape (2, 4) of f8 needs 64"));
  EXPECT_THAT(error_of([&] {
                parse(npy_with_header("{'descr': '<c16', 'fortran_order': False, 'shape': (3,), }\n", data));
              }),
              HasSubstr("unsupported dtype 'c16'"));
  EXPECT_THAT(error_of([&] {
                parse(npy_with_header("{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (6,), }\n", data));
              }),
              HasSubstr("structured"));
  EXPECT_THAT(error_of([&] { parse({1, 2, 3}); }), HasSubstr("x.npy: not a .npy array"));
}

TEST(NpyTest, ConvertsBetweenNumericTypes) {
  const NpyArray i8 = make_npy(std::vector<int64_t>{-3, 4});
  EXPECT_EQ(as_vector<double>(i8), (std::vector<double>{-3.0, 4.0}));
  EXPECT_EQ(as_vector<float>(make_npy(std::vector<uint8_t>{200})), std::vector<float>{200.f});
  EXPECT_EQ(as_vector<int>(make_npy(std::vector<double>{2.0, -7.0})), (std::vector<int>{2, -7}));
  EXPECT_THAT(error_of([] { as_vector<int>(make_npy(std::vector<double>{1.5}), "k"); }),
              HasSubstr("k: value 1.5 (dtype f8) is not a whole number"));
  EXPECT_THAT(error_of([] { as_vector<int>(make_npy(std::vector<uint32_t>{4294967295u}), "k"); }),
              HasSubstr("not in range"));
  EXPECT_THAT(error_of([] { as_vector<uint32_t>(make_npy(std::vector<int32_t>{-1}), "k"); }),
              HasSubstr("not unsigned"));
  EXPECT_THAT(error_of([] { as_vector<double>(make_npy_strings({"a"}, {1}), "k"); }),
              HasSubstr("k: expected a numeric array"));
}

TEST(NpyTest, ToEigenReadsRowMajorAndReshapes) {
  const NpyArray a = make_npy(std::vector<int32_t>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}, {2, 3, 2});
  const Eigen::MatrixXd m = to_eigen(a, 6, 2);
  EXPECT_EQ(m(0, 0), 1);
  EXPECT_EQ(m(0, 1), 2);
  EXPECT_EQ(m(1, 0), 3);
  EXPECT_EQ(m(5, 1), 12);
  EXPECT_THAT(error_of([&] { to_eigen(a, "k"); }), HasSubstr("k: expected at most 2 dimensions"));
  Eigen::MatrixXd r(2, 3);
  r << 1, 2, 3, 4, 5, 6;
  const NpyArray ra = make_npy(r);
  EXPECT_EQ(ra.shape, (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(as_vector<double>(ra), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(to_eigen(ra), r);
  EXPECT_EQ(to_eigen(make_npy(std::vector<double>{1, 2})).cols(), 1);
}

TEST_F(NpzTest, ErrorsNameTheFileAndKey) {
  NpzFile npz;
  npz.set("a", make_npy(std::vector<double>{1, 2, 3}));
  npz.set("b", make_npy_scalar(1));
  npz.write(path("x.npz"));
  const NpzFile r = NpzFile::read(path("x.npz"));
  EXPECT_THAT(error_of([&] { r.get("c"); }), HasSubstr(path("x.npz") + ": no array 'c' (it has: a, b)"));
  EXPECT_THAT(error_of([&] { r.get("a", {3, 1}); }),
              HasSubstr(path("x.npz") + ": array 'a' has shape (3,), expected (3, 1)"));
  EXPECT_NO_THROW(r.get("a", {-1}));
  EXPECT_THAT(error_of([] { NpzFile::read("/nonexistent/dir/m.npz"); }),
              HasSubstr("cannot read '/nonexistent/dir/m.npz': no such file"));
}

TEST_F(NpzTest, RefusesCorruptFiles) {
  write_bytes(path("garbage.npz"), std::vector<uint8_t>(300, 0x42));
  EXPECT_THAT(error_of([&] { NpzFile::read(path("garbage.npz")); }),
              HasSubstr(path("garbage.npz") + "': not a .npz (zip) archive"));

  NpzFile npz;
  std::vector<double> values(5000);
  for (size_t i = 0; i < values.size(); ++i) values[i] = std::sin(0.1 * i);
  npz.set("v", make_npy(values));
  npz.write(path("ok.npz"), NpzCompression::Deflate);
  std::vector<uint8_t> bytes = file_bytes(path("ok.npz"));

  std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + bytes.size() / 2);
  write_bytes(path("cut.npz"), cut);
  EXPECT_THAT(error_of([&] { NpzFile::read(path("cut.npz")); }), HasSubstr(path("cut.npz")));

  // Flip bytes inside the deflated data: the inflater or the CRC check must notice.
  std::vector<uint8_t> flipped = bytes;
  for (size_t i = 200; i < 260; ++i) flipped[i] ^= 0x5A;
  write_bytes(path("flip.npz"), flipped);
  EXPECT_THAT(error_of([&] { NpzFile::read(path("flip.npz")); }),
              HasSubstr(path("flip.npz") + ": array 'v'"));
}

TEST_F(NpzTest, EmptyArchiveRoundTrips) {
  NpzFile().write(path("empty.npz"));
  EXPECT_EQ(fs::file_size(path("empty.npz")), 22u);  // as numpy.savez writes it
  EXPECT_EQ(NpzFile::read(path("empty.npz")).size(), 0u);
}

TEST(NpyTest, MakeNpyChecksTheCount) {
  EXPECT_THAT(error_of([] { make_npy(std::vector<double>{1, 2, 3}, {2, 2}); }),
              HasSubstr("make_npy: 3 values do not fill shape (2, 2)"));
  EXPECT_THAT(error_of([] { make_npy(Eigen::MatrixXd::Zero(2, 3), {4}); }),
              HasSubstr("make_npy: 6 values do not fill shape (4,)"));
}

TEST_F(NpzTest, WriteNpyIsAtomicAndReadable) {
  const NpyArray a = make_npy(std::vector<float>{1, 2, 3, 4}, {2, 2});
  write_npy(path("sub/a.npy"), a);
  const NpyArray b = read_npy(path("sub/a.npy"));
  EXPECT_EQ(b.dtype, "f4");
  EXPECT_EQ(b.data, a.data);
  EXPECT_THAT(error_of([] { NpzFile().set("x", NpyArray{"f8", {2}, {1, 2, 3}}); }),
              HasSubstr("npz: array 'x': 3 data bytes, but shape (2,) of f8 needs 16"));
}

}  // namespace
}  // namespace bimart
