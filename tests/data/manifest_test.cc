#include "core/data/manifest.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/util/error.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

// The scratch folders of this process, removed when it exits.
const fs::path& scratch_root() {
  struct Root {
    fs::path dir = fs::temp_directory_path() / ("bimart_manifest_tests_" + std::to_string(::getpid()));
    ~Root() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  };
  static const Root root;
  return root.dir;
}

fs::path scratch(const std::string& name) {
  const fs::path p = scratch_root() / name;
  fs::remove_all(p);
  fs::create_directories(p / "seq");
  fs::create_directories(p / "objects" / "box");
  for (const char* f : {"seq/a.npz", "seq/b.npz", "seq/c.npz"}) std::ofstream(p / f) << "x";
  return p;
}

DatasetManifest example() {
  DatasetManifest m;
  m.generator = "bimart data synth 0.1.0";
  m.seed = 18446744073709551557ull;  // needs all 64 bits
  m.fps = 30;
  m.train = {"seq/a.npz", "seq/b.npz"};
  m.test = {"seq/c.npz"};
  m.objects = {{"box_3", "objects/box", "box", "train"}};
  return m;
}

void write_json(const fs::path& dir, const std::string& text) { std::ofstream(dir / "manifest.json") << text; }

std::string error_of(const fs::path& dir) {
  try {
    read_manifest(dir.string());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Manifest, RoundTripAndSplitFiles) {
  const fs::path dir = scratch("round_trip");
  write_manifest(example(), dir.string());
  const DatasetManifest m = read_manifest(dir.string());
  EXPECT_EQ(m.version, 1);
  EXPECT_EQ(m.generator, "bimart data synth 0.1.0");
  EXPECT_EQ(m.seed, 18446744073709551557ull);
  EXPECT_DOUBLE_EQ(m.fps, 30);
  EXPECT_EQ(m.train, example().train);
  EXPECT_EQ(m.test, example().test);
  ASSERT_EQ(m.objects.size(), 1u);
  EXPECT_EQ(m.objects[0].name, "box_3");
  EXPECT_EQ(m.objects[0].path, "objects/box");
  EXPECT_EQ(m.objects[0].category, "box");
  EXPECT_EQ(m.objects[0].split, "train");

  // The layout `bimart eval --split` reads: top-level lists of relative paths.
  nlohmann::json j;
  std::ifstream(dir / "manifest.json") >> j;
  EXPECT_EQ(j["format"], "bimart-dataset");
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["train"][1], "seq/b.npz");
  EXPECT_EQ(j["test"][0], "seq/c.npz");
  EXPECT_FALSE(fs::exists(dir / "manifest.json.tmp"));

  const std::vector<std::string> train = split_files(m, dir.string(), "train");
  ASSERT_EQ(train.size(), 2u);
  EXPECT_EQ(train[0], (dir / "seq" / "a.npz").string());
  EXPECT_EQ(split_files(m, dir.string(), "test")[0], (dir / "seq" / "c.npz").string());
  try {
    split_files(m, dir.string(), "tets");
    FAIL() << "unknown split accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'tets'"), std::string::npos) << what;
    EXPECT_NE(what.find("known: train, test"), std::string::npos) << what;
    EXPECT_NE(what.find("did you mean 'test'"), std::string::npos) << what;
  }
}

TEST(Manifest, MinimalHandWrittenManifestAndUnknownKeys) {
  const fs::path dir = scratch("minimal");
  write_json(dir, R"({"train": ["seq/a.npz"], "test": ["seq/c.npz"], "source": "my converter"})");
  const DatasetManifest m = read_manifest(dir.string());
  EXPECT_EQ(m.train, std::vector<std::string>{"seq/a.npz"});
  EXPECT_DOUBLE_EQ(m.fps, 30);  // default
  EXPECT_TRUE(m.objects.empty());
}

TEST(Manifest, ErrorsNameTheFileAndField) {
  const fs::path dir = scratch("errors");
  const std::string file = (dir / "manifest.json").string();
  auto expect = [&](const std::string& json, const std::vector<std::string>& parts) {
    write_json(dir, json);
    const std::string what = error_of(dir);
    ASSERT_FALSE(what.empty()) << "accepted: " << json;
    EXPECT_NE(what.find(file), std::string::npos) << what;
    for (const std::string& p : parts) EXPECT_NE(what.find(p), std::string::npos) << what;
  };
  expect(R"({"format": "bimart-sequences", "train": []})", {"\"format\"", "bimart-sequences", "bimart-dataset"});
  expect(R"({"format": "bimart-dataset", "version": 2, "train": []})", {"\"version\" is 2", "up to version 1"});
  expect(R"({"train": ["seq/a.npz", "seq/missing.npz", "seq/gone.npz"]})",
         {"2 listed files do not exist", "\"train\"[1]", "missing.npz"});
  expect(R"({"train": ["seq/a.npz"], "test": ["seq/./a.npz"]})", {"both \"train\" and \"test\""});
  expect(R"({"train": "seq/a.npz"})", {"\"train\" must be a list"});
  expect(R"({"train": [3]})", {"\"train\"[0]"});
  expect(R"({"fps": -30, "train": []})", {"\"fps\" must be a positive number"});
  expect(R"({"seed": -1, "train": []})", {"\"seed\""});
  expect(R"({"train": [], "objects": [{"name": "x", "path": "objects/none"}]})", {"\"objects\"[0]", "objects/none"});
  expect(R"({"generator": "x"})", {"lists no sequences"});
  expect(R"({"train": [)", {"not valid JSON"});
  expect(R"([1, 2])", {"JSON object"});
  fs::remove(dir / "manifest.json");
  EXPECT_NE(error_of(dir).find("manifest.json: missing"), std::string::npos) << error_of(dir);

  DatasetManifest bad = example();
  bad.version = 2;
  EXPECT_THROW(write_manifest(bad, dir.string()), Error);
  bad = example();
  bad.fps = 0;
  EXPECT_THROW(write_manifest(bad, dir.string()), Error);
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));
}

}  // namespace
}  // namespace bimart
