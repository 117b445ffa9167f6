// Turning a data set's objects about their hinges (core/data/turned_dataset.h): the world
// geometry of every frame is unchanged, the canonical frame is turned, the set reads back.
#include "core/data/turned_dataset.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/io/sequence.h"
#include "core/object/object_io.h"
#include "core/util/error.h"
#include "tests/data/tiny_dataset.h"

namespace bimart {
namespace {

TEST(TurnedDataset, WorldGeometryIsUnchangedAndTheCanonicalFrameTurns) {
  const ArticulatedObject o = make_object("laptop", 2);
  ObjectState s;
  s.angle = 0.7;
  s.root_rotation = Eigen::Vector3d(0.3, -1.1, 0.4);
  s.root_translation = Eigen::Vector3d(0.2, 0.1, -0.5);
  for (double deg : {90.0, 180.0, 270.0, 37.0}) {
    const double phi = deg * M_PI / 180;
    const ArticulatedObject t = turned_object(o, phi);
    const PosedObject a = pose_world(o, s), b = pose_world(t, turned_state(s, phi));
    EXPECT_LT((a.top - b.top).cwiseAbs().maxCoeff(), 1e-12) << deg;
    EXPECT_LT((a.bottom - b.bottom).cwiseAbs().maxCoeff(), 1e-12) << deg;
    // The canonical frame did turn: a quarter turn takes (x, y) to (−y, x), z kept.
    if (deg == 90.0) {
      EXPECT_NEAR(t.bottom.vertices(0, 0), -o.bottom.vertices(0, 1), 1e-12);
      EXPECT_NEAR(t.bottom.vertices(0, 1), o.bottom.vertices(0, 0), 1e-12);
      EXPECT_NEAR(t.bottom.vertices(0, 2), o.bottom.vertices(0, 2), 1e-12);
    }
  }
}

TEST(TurnedDataset, WritesTheSplitWithTurnedObjectsAndCompensatedStates) {
  const auto& tiny = testing_data::tiny_dataset();
  const auto out = tiny.dir.parent_path() / (tiny.dir.filename().string() + "_turned");
  std::filesystem::remove_all(out);
  const TurnedDatasetSummary s = write_turned_dataset(tiny.dir.string(), "train", {180}, out.string());
  EXPECT_EQ(s.objects, 1);
  EXPECT_EQ(s.sequences, 3);
  const DatasetManifest m = read_manifest(out.string());
  ASSERT_EQ(m.train.size(), 3u);
  EXPECT_TRUE(m.test.empty());
  const Sequence a = read_sequence((tiny.dir / "sequences" / "use_a.npz").string());
  const Sequence b = read_sequence((out / "sequences" / "use_a.npz").string());
  const ArticulatedObject oa = load_object(resolve_object_path(a, (tiny.dir / "sequences" / "use_a.npz").string()));
  const ArticulatedObject ob = load_object(resolve_object_path(b, (out / "sequences" / "use_a.npz").string()));
  for (std::int64_t t : {0, 50, 99}) {
    const PosedObject pa = pose_world(oa, ObjectState::from_row(a.object_states[t].contiguous().data_ptr<float>()));
    const PosedObject pb = pose_world(ob, ObjectState::from_row(b.object_states[t].contiguous().data_ptr<float>()));
    EXPECT_LT((pa.top - pb.top).cwiseAbs().maxCoeff(), 1e-5) << t;  // states stored as float32
    EXPECT_LT((pa.bottom - pb.bottom).cwiseAbs().maxCoeff(), 1e-5) << t;
  }
  EXPECT_TRUE(a.hands.hands[0].trans.equal(b.hands.hands[0].trans));  // hands are in the world frame
  EXPECT_THROW(write_turned_dataset(tiny.dir.string(), "train", {90}, out.string()), Error);  // no silent overwrite
  // Several turns: a copy each, named apart; the 0° copy is the original.
  const TurnedDatasetSummary several = write_turned_dataset(tiny.dir.string(), "test", {0, 90}, out.string(), true);
  EXPECT_EQ(several.objects, 2);
  EXPECT_EQ(several.sequences, 2);
  const DatasetManifest m2 = read_manifest(out.string());
  EXPECT_EQ(m2.test, (std::vector<std::string>{"sequences/test_d_t0.npz", "sequences/test_d_t90.npz"}));
  EXPECT_TRUE(m2.train.empty());
  const Sequence d0 = read_sequence((out / "sequences" / "test_d_t0.npz").string());
  const Sequence d = read_sequence((tiny.dir / "sequences" / "test_d.npz").string());
  EXPECT_EQ(d0.name, d.name + "_t0");
  EXPECT_TRUE(d0.object_states.allclose(d.object_states, 1e-6, 1e-6));
  EXPECT_FALSE(read_sequence((out / "sequences" / "test_d_t90.npz").string()).object_states.allclose(d.object_states, 1e-3, 1e-3));
  EXPECT_THROW(write_turned_dataset(tiny.dir.string(), "test", {}, out.string(), true), Error);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace bimart
