#include "core/synth/dataset.h"
#include "core/synth/dataset_check.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include <unistd.h>

#include "core/data/manifest.h"
#include "core/io/sequence.h"
#include "core/object/object_io.h"
#include "core/util/error.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

class Dataset : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("bimart_synth_" + std::to_string(::getpid()));
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  SynthOptions tiny(const std::string& name, std::uint64_t seed = 4) const {
    SynthOptions o;
    o.out = (root_ / name).string();
    o.categories = {"notebook", "box"};
    o.train_objects = 1;
    o.test_objects = 1;
    o.sequences_per_object = 2;
    o.seed = seed;
    o.progress = false;
    o.threads = 2;
    return o;
  }
  fs::path root_;
};

TEST_F(Dataset, WritesObjectsSequencesAndASplitByInstance) {
  SynthOptions o = tiny("a");
  o.preview = 1;
  const SynthSummary s = synthesize_dataset(o);
  EXPECT_EQ(s.objects, 4);
  EXPECT_EQ(s.train, 4);
  EXPECT_EQ(s.test, 4);
  EXPECT_EQ(s.failed, 0);
  ASSERT_EQ(s.previews.size(), 1u);
  EXPECT_TRUE(fs::exists(s.previews[0]));
  const DatasetManifest m = read_manifest(o.out);
  EXPECT_EQ(m.seed, 4u);
  ASSERT_EQ(m.objects.size(), 4u);
  for (const auto& obj : m.objects) {
    EXPECT_EQ(obj.split, obj.name.back() == '0' ? "train" : "test") << obj.name;
    EXPECT_NO_THROW(load_object((fs::path(o.out) / obj.path).string()));
  }
  int grabs = 0, uses = 0;
  for (const auto& split : {"train", "test"})
    for (const auto& f : split_files(m, o.out, split)) {
      const Sequence q = read_sequence(f);
      EXPECT_EQ(fs::path(resolve_object_path(q, f)).filename().string().rfind(q.category, 0), 0u);
      EXPECT_EQ(q.hands.hands[0].rot.size(0), q.num_frames());
      (q.kind == "grab" ? grabs : uses) += 1;
      // The split follows the object instance: the object's suffix _00 is train, _01 test.
      const std::string object_name = fs::path(q.object).filename().string();
      EXPECT_EQ(std::string(split), object_name.back() == '0' ? "train" : "test");
    }
  EXPECT_EQ(grabs, 4);
  EXPECT_EQ(uses, 4);
  // The data issue's bars on this set: both hands touch while the object moves, no hand
  // more than 5 mm inside the other.
  const DatasetCheck c = check_dataset(o.out, "train", 2);
  EXPECT_EQ(c.sequences, 4);
  ASSERT_GT(c.moving_frames, 0);
  EXPECT_GE(c.both_touching, 0.8 * static_cast<double>(c.moving_frames));
  EXPECT_EQ(c.use_sequences, 2);
  EXPECT_LT(c.hand_interpenetration, 0.005);
}

TEST_F(Dataset, SameSeedByteIdenticalFilesOtherSeedOtherFiles) {
  const SynthOptions a = tiny("a"), b = tiny("b"), c = tiny("c", 5);
  synthesize_dataset(a);
  SynthOptions b1 = b;
  b1.threads = 1;  // the thread count must not matter
  synthesize_dataset(b1);
  synthesize_dataset(c);
  const DatasetManifest m = read_manifest(a.out);
  for (const auto& f : m.train) {
    EXPECT_EQ(bytes_of(fs::path(a.out) / f), bytes_of(fs::path(b.out) / f)) << f;
    EXPECT_NE(bytes_of(fs::path(a.out) / f), bytes_of(fs::path(c.out) / f)) << f;
  }
  EXPECT_EQ(bytes_of(fs::path(a.out) / "manifest.json"), bytes_of(fs::path(b.out) / "manifest.json"));
  EXPECT_EQ(bytes_of(fs::path(a.out) / "objects/notebook_00/top.obj"), bytes_of(fs::path(b.out) / "objects/notebook_00/top.obj"));
}

TEST_F(Dataset, RefusesANonEmptyFolderUnlessForcedAndNeverAForeignOne) {
  const SynthOptions o = tiny("a");
  synthesize_dataset(o);
  EXPECT_THROW(synthesize_dataset(o), Error);
  SynthOptions forced = o;
  forced.force = true;
  forced.categories = {"box"};
  EXPECT_NO_THROW(synthesize_dataset(forced));
  EXPECT_EQ(read_manifest(o.out).objects.size(), 2u);  // the old notebook objects are gone
  EXPECT_FALSE(fs::exists(fs::path(o.out) / "objects/notebook_00"));
  // A folder with other files is never emptied.
  const fs::path foreign = root_ / "mine";
  fs::create_directories(foreign);
  std::ofstream(foreign / "thesis.tex") << "x";
  SynthOptions f = tiny("mine");
  f.force = true;
  EXPECT_THROW(synthesize_dataset(f), Error);
  EXPECT_TRUE(fs::exists(foreign / "thesis.tex"));
  SynthOptions bad = tiny("z");
  bad.categories = {"laptopp"};
  EXPECT_THROW(synthesize_dataset(bad), Error);
}

}  // namespace
}  // namespace bimart
