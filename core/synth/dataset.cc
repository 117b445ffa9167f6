#include "core/synth/dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <thread>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/data/manifest.h"
#include "core/hand/hand_model.h"
#include "core/hand/lbs.h"
#include "core/io/sequence.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"
#include "core/render/rasterizer.h"
#include "core/util/data_path.h"
#include "core/util/error.h"
#include "core/util/output_path.h"
#include "core/util/log.h"
#include "core/util/parallel.h"
#include "core/util/progress.h"
#include "core/version.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

// splitmix64: independent seeds for every object and sequence from the data set's seed,
// so each can be made on any thread, in any order, with the same result.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
std::uint64_t derive(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0) {
  return mix(mix(mix(seed) ^ a) ^ (b * 0x632be59bd9b4e019ULL));
}

struct ObjectJob {
  std::string category, name, split;
  std::uint64_t seed = 0;
  std::unique_ptr<ArticulatedObject> object;
  std::unique_ptr<ObjectDistance> distance;
};

struct SequenceJob {
  size_t object = 0;
  int index = 0;
  SequenceKind kind = SequenceKind::Grab;
  std::uint64_t seed = 0;
  std::string name, file;  // file relative to the data set folder
  bool written = false;
  bool preview = false;
  long frames = 0;
};

void prepare_folder(const SynthOptions& o) {
  if (o.out.empty()) throw Error("data synth: no output folder (--out)");
  std::error_code ec;
  if (fs::exists(o.out, ec) && !fs::is_directory(o.out, ec)) throw Error(o.out + ": exists and is not a folder");
  check_output_folder(o.out);  // writable, before anything is removed or computed
  if (fs::exists(o.out) && !fs::is_empty(o.out)) {
    if (!o.force)
      throw Error(o.out + ": not empty; choose another folder or pass --force to replace the data set in it");
    if (!fs::exists(fs::path(o.out) / "manifest.json") && !fs::exists(fs::path(o.out) / "sequences"))
      throw Error(o.out + ": not a bimart data set (no manifest.json or sequences/); refusing to replace it");
    for (const char* sub : {"manifest.json", "sequences", "objects", "preview", "cache"}) fs::remove_all(fs::path(o.out) / sub);
  }
  check_output_folder((fs::path(o.out) / "sequences").string());
  check_output_folder((fs::path(o.out) / "objects").string());
}

}  // namespace

void render_sequence_preview(const ArticulatedObject& object, const Trajectory& tr, const HandMotion& hands,
                             const std::array<const HandModel*, 2>& models, const std::string& png, int size) {
  const int n = tr.num_frames();
  const int mid = (tr.first_move + tr.last_move) / 2;
  const std::array<int, 4> frames{std::max(0, tr.first_move - 1), (tr.first_move + mid) / 2,
                                  (mid + tr.last_move) / 2, std::min(n - 1, tr.last_move + 2)};
  std::vector<Image> images;
  for (int f : frames) {
    const PosedObject p = pose_world(object, tr.states[static_cast<size_t>(f)]);
    TriangleMesh top{p.top, object.top.faces}, bottom{p.bottom, object.bottom.faces};
    std::array<TriangleMesh, 2> hand_mesh;
    for (int h = 0; h < 2; ++h) {
      const HandParams& hp = hands.hands[h];
      const auto row = [&](const at::Tensor& t, int dim) {
        Eigen::VectorXd v(dim);
        for (int k = 0; k < dim; ++k) v[k] = t.dim() == 1 ? t[k].item<double>() : t[f][k].item<double>();
        return v;
      };
      const Eigen::Vector3d rot = row(hp.rot, 3), trans = row(hp.trans, 3);
      const LbsResult<double> r = lbs<double>(*models[h], rot, row(hp.pose, 45), trans, row(hp.shape, 10));
      hand_mesh[h] = TriangleMesh{r.vertices, models[h]->faces};
    }
    const std::vector<RenderItem> items{{&bottom, {0.55, 0.62, 0.75}}, {&top, {0.85, 0.65, 0.45}},
                                        {&hand_mesh[0], {0.95, 0.80, 0.70}}, {&hand_mesh[1], {0.85, 0.72, 0.62}}};
    const Camera cam = frame_items(items, Eigen::Vector3d(0.25, -0.55, -1.0), 35);
    images.push_back(render(items, cam, size, size));
  }
  tile(images, 4).save_png(png);
}

SynthSummary synthesize_dataset(const SynthOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.train_objects < 1 || o.test_objects < 0 || o.sequences_per_object < 1)
    throw Error("data synth: need >= 1 train object, >= 0 test objects and >= 1 sequence per object");
  if (!(o.trajectory.fps > 0) || o.trajectory.min_frames < 60 || o.trajectory.max_frames < o.trajectory.min_frames)
    throw Error(fmt::format("data synth: need --fps > 0 and 60 <= --min-frames <= --max-frames (got {}, {}, {})",
                            o.trajectory.fps, o.trajectory.min_frames, o.trajectory.max_frames));
  std::vector<std::string> categories = o.categories.empty() ? object_categories() : o.categories;
  for (const auto& c : categories) object_family(c);  // unknown names fail here, with a hint
  const HandModel left = load_hand_model(o.mano_left.empty() ? find_data_file("models/hand/mano_left.npz") : o.mano_left);
  const HandModel right =
      load_hand_model(o.mano_right.empty() ? find_data_file("models/hand/mano_right.npz") : o.mano_right);
  if (left.side != HandSide::Left || right.side != HandSide::Right)
    throw Error("data synth: the hand models must be a left and a right hand");
  const std::array<const HandModel*, 2> models{&left, &right};
  prepare_folder(o);
  const int threads = resolve_threads(o.threads);
  at::set_num_threads(1);  // one sequence per thread

  // Objects: `train_objects` + `test_objects` instances of each category.
  std::vector<ObjectJob> objects;
  for (size_t c = 0; c < categories.size(); ++c)
    for (int k = 0; k < o.train_objects + o.test_objects; ++k) {
      ObjectJob j;
      j.category = categories[c];
      j.seed = derive(o.seed, std::hash<std::string>{}(categories[c]) & 0xffffffffULL, static_cast<std::uint64_t>(k)) % 1000000;
      j.name = fmt::format("{}_{:02d}", categories[c], k);
      j.split = k < o.train_objects ? "train" : "test";
      objects.push_back(std::move(j));
    }
  parallel_for(objects.size(), threads, [&](size_t i) {
    ObjectJob& j = objects[i];
    j.object = std::make_unique<ArticulatedObject>(make_object(j.category, j.seed));
    j.object->name = j.name;
    save_object(*j.object, (fs::path(o.out) / "objects" / j.name).string());
    j.distance = std::make_unique<ObjectDistance>(*j.object);
  });

  std::vector<SequenceJob> jobs;
  for (size_t i = 0; i < objects.size(); ++i)
    for (int s = 0; s < o.sequences_per_object; ++s) {
      SequenceJob j;
      j.object = i;
      j.index = s;
      j.kind = (s + static_cast<int>(i)) % 2 ? SequenceKind::Use : SequenceKind::Grab;
      j.seed = derive(o.seed, 0x5e0ULL + i, static_cast<std::uint64_t>(s));
      j.name = fmt::format("{}_{}_{:02d}", objects[i].name, kind_name(j.kind), s);
      j.file = "sequences/" + j.name + ".npz";
      jobs.push_back(std::move(j));
    }
  // Previews: the first grab and the first use of the first instance of each category.
  int previews = 0;
  for (auto& j : jobs)
    if (previews < o.preview && j.object % static_cast<size_t>(o.train_objects + o.test_objects) == 0 &&
        j.index < 2)
      j.preview = true, ++previews;

  SynthSummary summary;
  summary.objects = static_cast<int>(objects.size());
  if (o.preview > 0) fs::create_directories(fs::path(o.out) / "preview");
  {
    ProgressBar bar("synthesising", jobs.size(), o.progress);
    parallel_for(jobs.size(), threads, [&](size_t i) {
      SequenceJob& j = jobs[i];
      const ObjectJob& obj = objects[j.object];
      std::string why;
      // A new trajectory on each retry; the last ones switch between grab and use, so that
      // an object whose use is hard to plan (a small flip phone) still gets its sequences.
      const SequenceKind planned = j.kind;
      for (int retry = 0; retry < 5 && !j.written; ++retry) {
        const std::uint64_t s = derive(j.seed, static_cast<std::uint64_t>(retry));
        if (retry == 3) {
          j.kind = planned == SequenceKind::Grab ? SequenceKind::Use : SequenceKind::Grab;
          j.name = fmt::format("{}_{}_{:02d}", obj.name, kind_name(j.kind), j.index);
          j.file = "sequences/" + j.name + ".npz";
        }
        const Trajectory tr = plan_trajectory(*obj.object, j.kind, derive(s, 1), o.trajectory);
        try {
          Sequence seq;
          seq.hands = synthesize_hands(*obj.object, *obj.distance, models, tr, derive(s, 2), o.interaction);
          seq.name = j.name;
          seq.object = "../objects/" + obj.name;
          seq.category = obj.category;
          seq.kind = kind_name(j.kind);
          seq.fps = tr.fps;
          seq.object_states = tr.tensor();
          write_sequence(seq, (fs::path(o.out) / j.file).string());
          j.written = true;
          j.frames = tr.num_frames();
          if (j.preview)
            render_sequence_preview(*obj.object, tr, seq.hands, models,
                                    (fs::path(o.out) / "preview" / (j.name + ".png")).string());
        } catch (const Error& e) {
          why = e.what();
        }
      }
      if (!j.written) log::warn("{}: skipped: {}", j.name, why);
      bar.step();
    });
  }

  DatasetManifest m;
  m.generator = std::string("bimart data synth ") + BIMART_VERSION_STRING;
  m.seed = o.seed;
  m.fps = o.trajectory.fps;
  for (const auto& obj : objects) m.objects.push_back({obj.name, "objects/" + obj.name, obj.category, obj.split});
  for (const auto& j : jobs) {
    if (!j.written) {
      ++summary.failed;
      continue;
    }
    (objects[j.object].split == "train" ? m.train : m.test).push_back(j.file);
    (objects[j.object].split == "train" ? summary.train : summary.test) += 1;
    summary.frames += j.frames;
    if (j.preview) summary.previews.push_back((fs::path(o.out) / "preview" / (j.name + ".png")).string());
  }
  write_manifest(m, o.out);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace bimart
