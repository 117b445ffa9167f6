// glTF scenes, the viewer page and pictures (core/export): the scene read back and evaluated
// independently reproduces bimart's posed vertices; bad inputs are refused by the commands
// with clear errors and no files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/export/gltf_scene.h"
#include "core/export/scene_picture.h"
#include "core/export/viewer_page.h"
#include "core/hand/lbs.h"
#include "core/io/sequence.h"
#include "core/object/object_io.h"
#include "tests/cli/run_bimart.h"
#include "tests/outputs/gltf_eval.h"
#include "tests/outputs/scene_fixture.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;
using test::run_bimart;

struct Scene {
  std::array<HandModel, 2> shipped = test::shipped_hand_models();
  std::array<HandModel, 2> corrective{test::with_correctives(shipped[0]), test::with_correctives(shipped[1])};
  std::array<const HandModel*, 2> plain() const { return {&shipped[0], &shipped[1]}; }
  std::array<const HandModel*, 2> correctives() const { return {&corrective[0], &corrective[1]}; }
  ArticulatedObject object = make_object("box", 3);
};

const Scene& scene() {
  static const Scene s;
  return s;
}

double max_abs(const Eigen::MatrixX3d& a, const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& b) {
  return (a - Eigen::MatrixX3d(b)).cwiseAbs().maxCoeff();
}

TEST(GltfScene, ReproducesPosedHandsAndObject) {
  const Scene& sc = scene();
  const Sequence s = test::test_sequence(40, sc.correctives());
  GltfSummary sum;
  const tinygltf::Model m = test::load_glb(build_glb(s, sc.object, sc.correctives(), {}, &sum));
  // Every column is used (the poses are generic); those whose entry changes sign twice.
  for (int h = 0; h < 2; ++h) {
    EXPECT_GE(sum.morph_targets[h], 135);
    EXPECT_LE(sum.morph_targets[h], 270);
  }
  std::printf("morph targets: %d + %d for 135 + 135 corrective columns\n", sum.morph_targets[0], sum.morph_targets[1]);
  for (const auto& ch : m.animations[0].channels)
    if (ch.target_path == "weights")
      for (float w : test::read_accessor<float>(m, m.animations[0].samplers[ch.sampler].output)) {
        EXPECT_GE(w, 0.f);
        EXPECT_LE(w, 1.f + 1e-6f);
      }
  const at::Tensor states = s.object_states.to(at::kDouble).contiguous();
  double hand_err = 0, hand_err_lbs_only = 0, object_err = 0, corrective_size = 0;
  for (int t : {0, 17, 39}) {
    for (int h = 0; h < 2; ++h) {
      const int node = test::node_named(m, h == 0 ? "left_hand" : "right_hand");
      const LbsResult<double> want = test::posed_hand(s, *sc.correctives()[h], h, t);
      hand_err = std::max(hand_err, max_abs(test::node_vertices(m, node, t), want.vertices));
      hand_err_lbs_only = std::max(hand_err_lbs_only, max_abs(test::node_vertices(m, node, t, false), want.vertices));
      const LbsResult<double> plain = test::posed_hand(s, *sc.plain()[h], h, t);
      corrective_size = std::max(corrective_size, (want.vertices - plain.vertices).cwiseAbs().maxCoeff());
    }
    const PosedObject o = pose_world(sc.object, ObjectState::from_row(states[t].data_ptr<double>()));
    object_err = std::max(object_err, max_abs(test::node_vertices(m, test::node_named(m, "object_top"), t), o.top));
    object_err = std::max(object_err, max_abs(test::node_vertices(m, test::node_named(m, "object_bottom"), t), o.bottom));
  }
  std::printf("glTF vs bimart at frames 0, 17, 39: hands %.2e m, hands without morph targets %.2e m "
              "(correctives up to %.2e m), object %.2e m\n", hand_err, hand_err_lbs_only, corrective_size, object_err);
  EXPECT_LT(hand_err, 2e-5);
  EXPECT_LT(object_err, 2e-5);
  EXPECT_GT(hand_err_lbs_only, 1e-4);  // the morph targets do carry the correctives
}

TEST(GltfScene, StructureSkeletonsAndAnimation) {
  const Scene& sc = scene();
  const Sequence s = test::test_sequence(25, sc.plain(), 20.0);
  GltfSummary sum;
  const tinygltf::Model m = test::load_glb(build_glb(s, sc.object, sc.plain(), {}, &sum));
  EXPECT_EQ(sum.morph_targets[0], 0);  // the shipped hand's posedirs are all zero: no targets
  ASSERT_EQ(m.skins.size(), 2u);
  for (int h = 0; h < 2; ++h) {
    const auto names = gltf_joint_names(h == 0 ? HandSide::Left : HandSide::Right);
    ASSERT_EQ(m.skins[h].joints.size(), 16u);
    for (int j = 0; j < 16; ++j) EXPECT_EQ(m.nodes[m.skins[h].joints[j]].name, names[j]);
    // Parent of each joint node is the model's parent joint.
    for (int j = 1; j < 16; ++j) {
      const int parent = m.skins[h].joints[sc.shipped[h].parents[j]];
      const auto& kids = m.nodes[parent].children;
      EXPECT_NE(std::find(kids.begin(), kids.end(), m.skins[h].joints[j]), kids.end()) << names[j];
    }
  }
  ASSERT_EQ(m.animations.size(), 1u);
  const auto& times = m.accessors[m.animations[0].samplers[0].input];
  EXPECT_EQ(times.count, 25u);
  EXPECT_NEAR(times.maxValues.at(0), 24 / 20.0, 1e-6);
  EXPECT_EQ(m.scenes[0].extras.Get("frames").Get<int>(), 25);
  EXPECT_EQ(m.materials.size(), 4u);
  // three.js skins with the 4 largest weights, renormalised: how far that is from bimart.
  double four = 0;
  for (int t : {0, 12, 24})
    for (int h = 0; h < 2; ++h)
      four = std::max(four, (test::node_vertices(m, test::node_named(m, h == 0 ? "left_hand" : "right_hand"), t, true, 1) -
                             Eigen::MatrixX3d(test::posed_hand(s, *sc.plain()[h], h, t).vertices))
                                .rowwise().norm().maxCoeff());
  std::printf("4 influences per vertex (three.js): up to %.2f mm from bimart's vertices\n", 1e3 * four);
  EXPECT_LT(four, 0.01);
}

TEST(GltfScene, CorrectivesOffGivesNoMorphTargetsAndASmallerFile) {
  const Scene& sc = scene();
  const Sequence s = test::test_sequence(10, sc.correctives());
  GltfOptions off;
  off.correctives = false;
  GltfSummary a, b;
  const std::string with = build_glb(s, sc.object, sc.correctives(), {}, &a);
  const std::string without = build_glb(s, sc.object, sc.correctives(), off, &b);
  EXPECT_EQ(b.morph_targets[0] + b.morph_targets[1], 0);
  EXPECT_LT(without.size() * 3, with.size());
  EXPECT_TRUE(test::load_glb(without).meshes[2].primitives[0].targets.empty());
}

TEST(ViewerPage, EmbedsTheSceneAndTheContacts) {
  const Scene& sc = scene();
  Sequence s = test::test_sequence(12, sc.plain());
  test::add_contact_maps(s, sc.object, sc.plain());
  ViewerSample v;
  v.name = "a</script>";
  v.frames = 12;
  v.glb = build_glb(s, sc.object, sc.plain());
  v.contacts = viewer_contacts(s);
  v.top_vertices = sc.object.top.num_vertices();
  const std::string page = viewer_page({v, v}, "t", "/* bundle */");
  const std::string open = "<script type=\"application/json\" id=\"bimart-data\">";
  const size_t begin = page.find(open) + open.size(), end = page.find("</script>", begin);
  ASSERT_NE(end, std::string::npos);
  const nlohmann::json data = nlohmann::json::parse(page.substr(begin, end - begin));
  ASSERT_EQ(data["samples"].size(), 2u);
  EXPECT_EQ(data["samples"][0]["name"], "a</script>");
  // The contact highlights are the contact-map entries below 5 mm.
  const at::Tensor close = (s.contact_maps < kViewerContactDistance);
  std::int64_t hits = 0;
  for (const auto& f : data["samples"][0]["contacts"]["frames"]) hits += f.size() / 2;
  EXPECT_EQ(hits, close.sum().item<std::int64_t>());
  EXPECT_EQ(page.find("http://"), std::string::npos);
  EXPECT_EQ(page.find("https://"), std::string::npos);
}

// A directed run's marks: ranges cut to the sequence, regions on their part, and a pose pin's
// wrist exactly the sample's at its own frame and carried rigidly with the object after it.
TEST(ViewerPage, MarksConstraintsPinsAndRedrawnStretch) {
  const Scene& sc = scene();
  const fs::path dir = fs::temp_directory_path() / ("bimart_marks_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Sequence s = test::test_sequence(30, sc.plain());
  write_sequence(s, (dir / "sample.npz").string());
  SceneSource src{(dir / "sample.npz").string(), s, sc.object, std::make_shared<std::array<HandModel, 2>>(sc.shipped)};

  HandConstraints c;
  const Eigen::Vector3d on_top = sc.object.top.vertices.row(5).transpose(),
                        on_bottom = sc.object.bottom.vertices.row(7).transpose();
  c.contacts.push_back({1, {0, 20}, ContactPart::Top, ContactRegion{on_top, 0.03}, 0.03, {}});
  c.contacts.push_back({0, {5, 10}, ContactPart::None, std::nullopt, 0.03, {}});
  c.contacts.push_back({0, {11, 15}, ContactPart::Any, ContactRegion{on_bottom, 0.02}, 0.03, {}});
  HandPin wrist;
  wrist.hand = 0;
  wrist.frames = {12, 12};
  wrist.wrist = Eigen::Vector3d(0.1, 0.2, 0.3);
  HandPin pose;
  pose.hand = 1;
  pose.frames = {25, 40};  // past the last frame: cut to 29
  pose.source = (dir / "sample.npz").string();
  pose.source_frame = 25;
  c.pins = {wrist, pose};
  c.keep = KeptSample{"sample.npz", {10, 20}, true, 8};

  const std::vector<ViewerMark> m = viewer_marks(c, src);
  ASSERT_EQ(m.size(), 7u);
  EXPECT_EQ(m[0].kind, "top");
  EXPECT_EQ(m[0].region_part, "top");
  EXPECT_NE(m[0].label.find("right: on the top part within 3 cm of a point, frames 0-20"), std::string::npos) << m[0].label;
  EXPECT_EQ(m[1].kind, "none");
  EXPECT_FALSE(m[1].region_point);
  EXPECT_EQ(m[2].region_part, "bottom");  // `any` with a point on the bottom part
  EXPECT_EQ(m[3].kind, "wrist");
  ASSERT_EQ(m[3].wrists.size(), 1u);
  EXPECT_EQ(m[3].wrists[0], (std::array<double, 3>{0.1, 0.2, 0.3}));
  EXPECT_EQ(m[4].kind, "pose");
  EXPECT_EQ(m[4].last, 29);
  ASSERT_EQ(m[4].wrists.size(), 5u);
  const HandParams& r = s.hands.hands[1];
  const auto vec = [](const at::Tensor& t) {
    const at::Tensor d = t.to(at::kDouble).contiguous();
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(d.data_ptr<double>(), d.numel()));
  };
  const Eigen::Vector3d j0 = lbs<double>(sc.shipped[1], Eigen::Vector3d(vec(r.rot[25])), vec(r.pose[25]),
                                         Eigen::Vector3d(vec(r.trans[25])), vec(r.shape))
                                 .joints.row(0)
                                 .transpose();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m[4].wrists[0][k], j0[k], 1e-6);
  const auto to_object = [&](int f) {
    const Eigen::Vector3d w(m[4].wrists[f - 25].data());
    return (object_pose_at(s.object_states, f).inverse() * w).eval();
  };
  for (int f = 26; f <= 29; ++f) EXPECT_LT((to_object(f) - to_object(25)).norm(), 1e-6) << "frame " << f;
  EXPECT_EQ(m[5].kind, "redraw");
  EXPECT_EQ(m[5].hand, -1);
  EXPECT_EQ(m[5].first, 10);
  EXPECT_EQ(m[6].kind, "contacts");
  EXPECT_EQ(m[6].last, 29);

  ViewerSample v;
  v.name = "directed";
  v.frames = 30;
  v.glb = "x";
  v.marks = m;
  const std::string page = viewer_page({v}, "t", "/* bundle */");
  const std::string open = "<script type=\"application/json\" id=\"bimart-data\">";
  const size_t begin = page.find(open) + open.size();
  const nlohmann::json data = nlohmann::json::parse(page.substr(begin, page.find("</script>", begin) - begin));
  ASSERT_EQ(data["samples"][0]["marks"].size(), 7u);
  EXPECT_EQ(data["samples"][0]["marks"][4]["wrists"].size(), 5u);
  EXPECT_EQ(data["samples"][0]["marks"][0]["region"]["part"], "top");
  fs::remove_all(dir);
}

TEST(ViewerPage, ThreeHundredFramesStayUnderTenMegabytes) {
  const Scene& sc = scene();
  for (bool correctives : {false, true}) {
    const auto models = correctives ? sc.correctives() : sc.plain();
    Sequence s = test::test_sequence(300, models);
    ViewerSample v;
    v.name = "long";
    v.frames = 300;
    v.glb = build_glb(s, sc.object, models);
    std::string bundle(700000, ' ');  // about the size of the three.js bundle
    const std::size_t size = viewer_page({v}, "t", bundle).size();
    std::printf("300-frame page, %s: glb %.2f MB, page %.2f MB (with a 0.70 MB script)\n",
                correctives ? "135 correctives per hand" : "shipped hands", v.glb.size() / 1e6, size / 1e6);
    EXPECT_LT(size, 10'000'000u);
  }
}

TEST(ScenePicture, ShowsHandsAndObjectAtEachFrame) {
  const Scene& sc = scene();
  SceneSource src;
  src.sequence = test::test_sequence(31, sc.plain());
  src.object = sc.object;
  src.hands = std::make_shared<std::array<HandModel, 2>>(sc.shipped);
  const Image img = render_sequence_frames(src, {0, 15, 30}, 96);
  ASSERT_EQ(img.width, 3 * 96);
  ASSERT_EQ(img.height, 96);
  for (int tile = 0; tile < 3; ++tile) {
    int drawn = 0;
    for (int y = 0; y < 96; ++y)
      for (int x = tile * 96; x < (tile + 1) * 96; ++x) {
        const std::uint8_t* p = &img.rgb[3 * (y * img.width + x)];
        drawn += !(p[0] == 255 && p[1] == 255 && p[2] == 255);
      }
    EXPECT_GT(drawn, 200) << "tile " << tile;
  }
  EXPECT_THROW(render_sequence_frames(src, {31}, 96), Error);
}

// ---- The commands, with bad inputs -------------------------------------------------------

struct Files {
  fs::path dir = fs::temp_directory_path() / ("bimart_outputs_test_" + std::to_string(::getpid()));
  fs::path seq = dir / "seq.npz";
  Files() {
    fs::remove_all(dir);
    save_object(scene().object, (dir / "box").string());
    write_sequence(test::test_sequence(20, scene().plain()), seq.string());
  }
  ~Files() { fs::remove_all(dir); }
};

const Files& files() {
  static const Files f;
  return f;
}

TEST(ExportCommand, WritesOneGlbPerSequence) {
  const fs::path out = files().dir / "out";
  const auto r = run_bimart("export " + files().seq.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("20 frames at 30 fps"), std::string::npos) << r.output;
  EXPECT_EQ(test::load_glb([&] {
              std::ifstream in(out / "seq.glb", std::ios::binary);
              return std::string(std::istreambuf_iterator<char>(in), {});
            }()).skins.size(), 2u);
}

TEST(ExportCommand, RefusesTwoSequencesOfOneName) {
  fs::create_directories(files().dir / "again");
  const fs::path twin = files().dir / "again" / "seq.npz";
  Sequence s = read_sequence(files().seq.string());
  s.object = "../box";
  write_sequence(s, twin.string());
  const fs::path out = files().dir / "out_twins";
  const auto r = run_bimart("export " + files().seq.string() + " " + twin.string() + " --out " + out.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("would both be written as seq.glb"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(ExportCommand, RefusesATruncatedFile) {
  const fs::path bad = files().dir / "truncated.npz";
  fs::copy_file(files().seq, bad, fs::copy_options::overwrite_existing);
  fs::resize_file(bad, fs::file_size(bad) / 2);
  const fs::path out = files().dir / "out_truncated";
  const auto r = run_bimart("export " + bad.string() + " --out " + out.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("truncated.npz"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(ExportCommand, RefusesASequenceOfAnotherHandModel) {
  // Vertices of another model (50 vertices) stored with the sequence.
  Sequence s = test::test_sequence(6, scene().plain());
  s.hands.vertices = at::zeros({2, 6, 50, 3});
  const fs::path other = files().dir / "other_model.npz";
  s.object = "box";
  write_sequence(s, other.string());
  const fs::path out = files().dir / "out_other";
  auto r = run_bimart("export " + other.string() + " --out " + out.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("other_model.npz: hand_vertices has 50 vertices per hand, but the left hand model has"),
            std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // Same vertex count, other shape: the stored vertices are not reproduced.
  HandModel big = scene().shipped[0];
  big.v_template *= 1.2;
  HandModel big_r = scene().shipped[1];
  big_r.v_template *= 1.2;
  s = test::test_sequence(6, scene().plain());
  s.object = "box";
  at::Tensor v = at::zeros({2, 6, big.num_vertices(), 3}, at::kDouble);
  for (int h = 0; h < 2; ++h)
    for (int t = 0; t < 6; ++t) {
      const LbsResult<double> p = test::posed_hand(s, h == 0 ? big : big_r, h, t);
      v[h][t].copy_(at::from_blob(const_cast<double*>(p.vertices.data()), {p.vertices.rows(), 3}, at::kDouble));
    }
  s.hands.vertices = v.to(at::kFloat);
  write_sequence(s, other.string());
  r = run_bimart("view " + other.string() + " --out " + (out / "v.html").string());
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(r.output.find("does not reproduce the stored hand_vertices") != std::string::npos ||
              r.output.find("viewer script") != std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // A hand model file that does not exist.
  r = run_bimart("export " + files().seq.string() + " --out " + out.string() + " --mano-left " +
                 (files().dir / "nope_left.npz").string() + " --mano-right " + (files().dir / "nope_right.npz").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("nope_left.npz"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(ExportCommand, ReadOnlyFolderIsAClearErrorAndLeavesNothing) {
  // root ignores permission bits: then use a folder no one can create files in (procfs).
  fs::path ro = files().dir / "read_only";
  if (::geteuid() == 0) {
    ro = "/proc/bimart_outputs_test";
  } else {
    fs::create_directories(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  }
  for (const std::string& cmd : {"export " + files().seq.string() + " --out " + ro.string(),
                                "render " + files().seq.string() + " --frames 0,5 --size 32 --out " + (ro / "f.png").string()}) {
    const auto r = run_bimart(cmd);
    EXPECT_NE(r.status, 0) << cmd;
    EXPECT_NE(r.output.find(ro.string()), std::string::npos) << r.output;
  }
  std::error_code ec;
  if (fs::is_directory(ro, ec)) {
    EXPECT_TRUE(fs::is_empty(ro));
    fs::permissions(ro, fs::perms::owner_all);
  }
}

TEST(RenderCommand, WritesAPicture) {
  const fs::path png = files().dir / "frames.png";
  const auto r = run_bimart("render " + files().seq.string() + " --frames 0,10,19 --size 64 --out " + png.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("192x64"), std::string::npos) << r.output;
  EXPECT_GT(fs::file_size(png), 500u);
  const auto bad = run_bimart("render " + files().seq.string() + " --frames 0,20 --out " + png.string());
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("frame 20 is out of range"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace bimart
