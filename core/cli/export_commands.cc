// bimart export, view and render: the files people open (docs/outputs.md) from sequence
// files (docs/formats.md, "Sequence"): .glb scenes, the viewer page, a PNG of chosen frames.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "core/cli/command.h"
#include "core/export/gltf_scene.h"
#include "core/export/scene_picture.h"
#include "core/export/scene_source.h"
#include "core/export/viewer_page.h"
#include "core/util/error.h"
#include "core/util/atomic_file.h"

namespace bimart::cli {
namespace {

namespace fs = std::filesystem;

struct ExportOptions {
  std::vector<std::string> sequences;
  std::string out, mano_left, mano_right, title, frames = "0,30,60", hands;
  bool no_correctives = false, measure_contacts = false;
  int size = 480, columns = 0;
};

void add_hand_options(CLI::App* cmd, ExportOptions& o) {
  cmd->add_option("--mano-left", o.mano_left, "left hand model .npz the sequences were made with (default: the shipped hand)");
  cmd->add_option("--mano-right", o.mano_right, "right hand model .npz (give both or neither)");
}

std::vector<SceneSource> load_all(const ExportOptions& o) {
  const auto hands = load_export_hands(o.mano_left, o.mano_right);
  std::vector<SceneSource> out;
  for (const auto& path : o.sequences) out.push_back(load_scene_source(path, hands));
  return out;
}

GltfOptions gltf_options(const ExportOptions& o) {
  GltfOptions g;
  g.correctives = !o.no_correctives;
  return g;
}

int run_export(const ExportOptions& o) {
  const auto sources = load_all(o);
  // Every scene is built before the first file is written.
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<GltfSummary> sums;
  std::map<std::string, std::string> written;  // output -> sequence, to refuse two sequences of one stem
  for (const auto& s : sources) {
    const std::string stem = fs::path(s.path).stem().string();
    if (auto [it, fresh] = written.emplace(stem, s.path); !fresh)
      throw Error(fmt::format("bimart export: {} and {} would both be written as {}.glb; export them to different folders",
                              it->second, s.path, stem));
    GltfSummary sum;
    std::string bytes = build_glb(s.sequence, s.object, s.models(), gltf_options(o), &sum);
    files.emplace_back((fs::path(o.out) / (fs::path(s.path).stem().string() + ".glb")).string(), std::move(bytes));
    sums.push_back(sum);
  }
  for (size_t i = 0; i < files.size(); ++i) {
    const auto& [path, bytes] = files[i];
    write_file_atomically(path, [&](std::ostream& f) { f.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
    std::cout << fmt::format("wrote {} ({:.2f} MB, {} frames at {} fps, {} + {} corrective morph targets)\n", path,
                             bytes.size() / 1e6, sums[i].frames, sources[i].sequence.fps, sums[i].morph_targets[0],
                             sums[i].morph_targets[1]);
  }
  return 0;
}

int run_view(const ExportOptions& o) {
  viewer_bundle_path();  // before any work
  const auto sources = load_all(o);
  std::vector<ViewerSample> samples;
  for (const auto& s : sources) {
    ViewerSample v;
    v.name = s.sequence.name;
    v.fps = s.sequence.fps;
    v.frames = s.sequence.num_frames();
    v.glb = build_glb(s.sequence, s.object, s.models(), gltf_options(o));
    v.contacts = viewer_contacts(s.sequence);
    if (v.contacts.empty() && o.measure_contacts) v.contacts = measured_contacts(s);
    v.top_vertices = s.object.top.num_vertices();
    if (!o.hands.empty()) v.marks = viewer_marks(read_hand_constraints_for_sample(o.hands, s.path, s.sequence.fps), s);
    samples.push_back(std::move(v));
  }
  const std::string title = o.title.empty() ? "bimart: " + samples.front().name : o.title;
  const auto bytes = write_viewer_page(samples, title, o.out);
  std::cout << fmt::format("wrote {} ({:.2f} MB, {} sample{})\n", o.out, bytes / 1e6, samples.size(),
                           samples.size() == 1 ? "" : "s");
  return 0;
}

std::vector<std::int64_t> parse_frames(const std::string& text) {
  std::vector<std::int64_t> out;
  std::stringstream in(text);
  for (std::string t; std::getline(in, t, ',');) {
    t.erase(0, t.find_first_not_of(' '));
    t.erase(t.find_last_not_of(' ') + 1);
    try {
      size_t used = 0;
      out.push_back(std::stoll(t, &used));
      if (used != t.size()) throw std::invalid_argument(t);
    } catch (const std::exception&) {
      throw Error("--frames: '" + t + "' is not a frame number (give e.g. 0,30,60)");
    }
  }
  return out;
}

int run_render(const ExportOptions& o) {
  const auto frames = parse_frames(o.frames);
  const auto sources = load_all(o);
  const Image image = render_sequence_frames(sources.front(), frames, o.size, o.columns);
  image.save_png(o.out);
  std::cout << fmt::format("wrote {} ({}x{}, frames {})\n", o.out, image.width, image.height, o.frames);
  return 0;
}

}  // namespace

void add_export_commands(CLI::App& app, Commands& out) {
  static ExportOptions ex, vw, rd;
  {
    CLI::App* cmd = app.add_subcommand("export", "write each sequence as a binary glTF scene (.glb) for Blender and glTF viewers");
    cmd->add_option("sequences", ex.sequences, "sequence files (.npz)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--out", ex.out, "folder for <sequence stem>.glb")->required();
    cmd->add_flag("--no-correctives", ex.no_correctives, "leave out the pose-corrective morph targets (lighter files)");
    add_hand_options(cmd, ex);
    out.push_back({cmd, [] { return run_export(ex); }, false});
  }
  {
    CLI::App* cmd = app.add_subcommand("view", "write a self-contained HTML viewer of one or more sequences (samples)");
    cmd->add_option("sequences", vw.sequences, "sequence files (.npz), e.g. several samples of one trajectory")
        ->required()->check(CLI::ExistingFile);
    cmd->add_option("--out", vw.out, "the page to write (.html)")->required();
    cmd->add_option("--title", vw.title, "page title (default: the first sequence's name)");
    cmd->add_flag("--no-correctives", vw.no_correctives, "leave out the pose-corrective morph targets");
    cmd->add_flag("--measure-contacts", vw.measure_contacts,
                  "for sequences without a contact map: highlight object vertices within 5 mm of the posed hands");
    cmd->add_option("--hands", vw.hands,
                    "the trajectory file (or a file with a `hands:` block) the samples were directed with: "
                    "mark its constraints and pins (docs/directing.md)")
        ->check(CLI::ExistingFile);
    add_hand_options(cmd, vw);
    out.push_back({cmd, [] { return run_view(vw); }, false});
  }
  {
    CLI::App* cmd = app.add_subcommand("render", "a PNG of a sequence at chosen frames (hands and object, left to right)");
    cmd->add_option("sequence", rd.sequences, "a sequence file (.npz)")->required()->expected(1)->check(CLI::ExistingFile);
    cmd->add_option("--frames", rd.frames, "frames to draw, comma-separated")->capture_default_str();
    cmd->add_option("--out", rd.out, "the picture to write (.png)")->required();
    cmd->add_option("--size", rd.size, "pixels per frame (square)")->capture_default_str()->check(CLI::Range(16, 4096));
    cmd->add_option("--columns", rd.columns, "frames per row (default: all in one row)")->check(CLI::NonNegativeNumber);
    add_hand_options(cmd, rd);
    out.push_back({cmd, [] { return run_render(rd); }, false});
  }
}

}  // namespace bimart::cli
