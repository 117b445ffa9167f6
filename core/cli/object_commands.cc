// bimart object make | import | list | info | gallery: procedural objects, a user's meshes,
// object files, a picture of all categories.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <tuple>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/object/families/families.h"
#include "core/object/mesh_repair.h"
#include "core/object/object_import.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"
#include "core/render/rasterizer.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/text.h"

namespace bimart::cli {

namespace {

int make(const std::string& category, std::uint64_t seed, const std::string& out) {
  const ArticulatedObject o = make_object(category, seed);
  save_object(o, out);
  std::cout << fmt::format("wrote {} ({} + {} vertices) to {}\n", o.name, o.top.num_vertices(),
                           o.bottom.num_vertices(), out);
  return 0;
}

int info(const std::string& path) {
  ObjectLoadReport report;
  const ArticulatedObject o = load_object(path, &report);
  std::cout << fmt::format("name        {}\ncategory    {}\nsource      {}\n", o.name,
                           o.category.empty() ? "-" : o.category, o.units_note);
  for (const auto& [label, mesh, rep] : {std::tuple{"top", &o.top, &report.top}, {"bottom", &o.bottom, &report.bottom}})
    std::cout << fmt::format("{:<11} {} vertices, {} faces, {}, radius {:.4f} m; {}\n", label, mesh->num_vertices(),
                             mesh->num_faces(), is_closed_mesh(*mesh) ? "closed" : "OPEN", bounding_radius(*mesh),
                             rep->str());
  std::cout << fmt::format("scale s_o   {:.6f} (1/m)\nlimits      [{:.4f}, {:.4f}] rad = [{:.1f}, {:.1f}] deg\n"
                           "open angle  {:.4f} rad\n",
                           object_scale(o), o.angle_min, o.angle_max, o.angle_min * 180 / M_PI,
                           o.angle_max * 180 / M_PI, o.open_angle);
  return 0;
}

struct ImportArgs {
  std::vector<std::string> meshes;
  std::string top, out, units = "m", name, category;
  std::vector<double> pivot, axis, through, limits;
  double open = NAN;
  bool force = false;
};

int import(const ImportArgs& a) {
  check_object_output(a.out, a.force);  // before any work
  namespace fs = std::filesystem;
  auto same = [](const std::string& x, const std::string& y) {
    std::error_code ec;
    return x == y || fs::equivalent(x, y, ec);
  };
  ImportOptions o;
  if (a.meshes.size() == 1) {  // one OBJ, parts labelled by groups
    o.labelled = a.meshes[0];
    o.top_label = a.top;
  } else {
    if (same(a.meshes[0], a.meshes[1])) throw Error("the two mesh files are the same file: " + a.meshes[0]);
    if (same(a.top, a.meshes[0])) {
      o.top = a.meshes[0];
      o.bottom = a.meshes[1];
    } else if (same(a.top, a.meshes[1])) {
      o.top = a.meshes[1];
      o.bottom = a.meshes[0];
    } else {
      throw Error("--top " + a.top + " is neither of the two mesh files (" + a.meshes[0] + ", " + a.meshes[1] + ")");
    }
  }
  if (!a.through.empty()) {
    o.hinge = hinge_through({a.through[0], a.through[1], a.through[2]}, {a.through[3], a.through[4], a.through[5]});
  } else if (!a.pivot.empty() && !a.axis.empty()) {
    o.hinge = {{a.pivot[0], a.pivot[1], a.pivot[2]}, {a.axis[0], a.axis[1], a.axis[2]}};
  } else {
    throw Error("give the hinge: --pivot X Y Z with --axis X Y Z, or --through X1 Y1 Z1 X2 Y2 Z2");
  }
  o.units = a.units;
  o.name = a.name.empty() ? fs::absolute(a.out).lexically_normal().filename().string() : a.name;
  if (o.name.empty()) o.name = "imported";
  o.category = a.category;
  if (!a.limits.empty()) o.limits = std::pair{a.limits[0] * M_PI / 180, a.limits[1] * M_PI / 180};
  if (!std::isnan(a.open)) o.open_angle = a.open * M_PI / 180;
  ImportReport report;
  const ArticulatedObject obj = import_object(o, &report);
  write_object_folder(obj, a.out, a.force);
  std::cout << report.str();
  for (const std::string& w : report.warnings) log::warn("{}", w);
  std::cout << fmt::format("limits  [{:.1f}, {:.1f}] deg, open {:.1f} deg\nwrote {} to {}\n", obj.angle_min * 180 / M_PI,
                           obj.angle_max * 180 / M_PI, obj.open_angle * 180 / M_PI, obj.name, a.out);
  return 0;
}

// The family table as Markdown (docs/objects.md pastes it).
int list() {
  std::cout << "| category | what | dimensions (m) | hinge limits (deg) | open (deg) |\n|---|---|---|---|---|\n";
  for (const auto& f : object_families()) {
    std::vector<std::string> dims;
    for (const auto& d : f.dimensions) dims.push_back(fmt::format("{} {:g}–{:g}", d.name, d.min, d.max));
    std::cout << fmt::format("| `{}` | {} | {} | {:.0f} – {:.0f} | {:.0f} |\n", f.name, f.description,
                             join(dims, "; "), f.angle_min * 180 / M_PI, f.angle_max * 180 / M_PI,
                             f.open_angle * 180 / M_PI);
  }
  return 0;
}

int gallery(const std::string& out, int size, int columns) {
  // View direction (eye towards object) and up vector per frame layout (families.h).
  struct View {
    Eigen::Vector3d dir, up;
  };
  const View standard{{1.0, -0.8, -1.3}, {0, 1, 0}};
  const std::map<std::string, View> special = {
      {"microwave", {{-1.0, -1.3, -0.6}, {0, 0, 1}}},  // stands along z, door on y = 0
      {"scissors", {{-0.1, 0.25, -1.0}, {0, 1, 0}}},  // lies in the plane z = 0
  };
  std::vector<Image> tiles;
  for (const std::string& category : object_categories()) {
    const ArticulatedObject o = make_object(category, 1);
    const double angle = 0.5 * (o.angle_min + o.angle_max);
    const TriangleMesh top = posed_top(o, angle);
    const std::vector<RenderItem> items = {{&top, {0.90, 0.45, 0.20}}, {&o.bottom, {0.35, 0.55, 0.85}}};
    const auto it = special.find(category);
    const View& v = it == special.end() ? standard : it->second;
    Camera cam = frame_items(items, v.dir.normalized());
    cam.up = v.up;
    tiles.push_back(render(items, cam, size, size));
    log::info("{}: {} + {} vertices, angle {:.2f} rad", o.name, o.top.num_vertices(), o.bottom.num_vertices(), angle);
  }
  tile(tiles, columns).save_png(out);
  std::cout << "wrote " << out << "\n";
  return 0;
}

}  // namespace

void add_object_commands(CLI::App& app, Commands& out) {
  CLI::App* object = app.add_subcommand("object", "articulated objects: make, inspect, picture");
  object->require_subcommand(1);

  static std::string category, dir;
  static std::uint64_t seed = 0;
  CLI::App* make_cmd = object->add_subcommand("make", "write a procedural object (top.obj, bottom.obj, object.yaml)");
  make_cmd->add_option("--category", category, "one of: " + join(object_categories(), ", "))->required();
  add_seed_option(make_cmd, seed, "random seed for the dimensions (default 0)");
  make_cmd->add_option("--out", dir, "output folder")->required();
  out.push_back({make_cmd, [] { return make(category, seed, dir); }, false});

  static ImportArgs imp;
  CLI::App* import_cmd = object->add_subcommand(
      "import", "your own object: two part meshes and the hinge, written canonical (docs/trajectories.md)");
  import_cmd
      ->add_option("meshes", imp.meshes,
                   "the two part meshes (OBJ, PLY, OFF or STL), or one OBJ whose groups (g/o lines) label the parts")
      ->expected(1, 2)
      ->required();
  import_cmd
      ->add_option("--top", imp.top,
                   "which part moves (the lid, screen, cap, ...): one of the two files, or the group name in one OBJ")
      ->required();
  CLI::Option* pivot = import_cmd->add_option("--pivot", imp.pivot, "a point on the hinge axis (X Y Z, in --units)")
                           ->expected(3);
  CLI::Option* axis =
      import_cmd->add_option("--axis", imp.axis, "the hinge direction (X Y Z); a positive angle opens about it")
          ->expected(3);
  CLI::Option* through =
      import_cmd
          ->add_option("--through", imp.through, "two points on the hinge axis (X1 Y1 Z1 X2 Y2 Z2), directed 1 -> 2")
          ->expected(6);
  through->excludes(pivot)->excludes(axis);
  pivot->needs(axis);
  axis->needs(pivot);
  import_cmd->add_option("--units", imp.units, "units of the meshes and the hinge point: m, cm or mm")
      ->check(CLI::IsMember({"m", "cm", "mm"}))
      ->capture_default_str();
  import_cmd->add_option("--out", imp.out, "output folder (top.obj, bottom.obj, object.yaml)")->required();
  import_cmd->add_option("--name", imp.name, "object name (default: the output folder's name)");
  import_cmd->add_option("--category", imp.category, "a procedural category whose hinge limits to take");
  import_cmd->add_option("--limits", imp.limits, "hinge limits MIN MAX (degrees; default the category's, else 0 180)")
      ->expected(2);
  import_cmd->add_option("--open", imp.open, "a typical open angle (degrees; default the middle of the limits)");
  import_cmd->add_flag("--force", imp.force, "replace an object already in --out");
  out.push_back({import_cmd, [] { return import(imp); }, false});

  CLI::App* list_cmd = object->add_subcommand("list", "the procedural categories: dimension ranges, hinge limits");
  out.push_back({list_cmd, [] { return list(); }, false});

  static std::string path;
  CLI::App* info_cmd = object->add_subcommand("info", "load an object (object.yaml or ARCTIC folder) and describe it");
  info_cmd->add_option("path", path, "object.yaml, or a folder holding it, or an ARCTIC template folder")->required();
  out.push_back({info_cmd, [] { return info(path); }, false});

  static std::string png = "docs/images/object_gallery.png";
  static int size = 256, columns = 4;
  CLI::App* gallery_cmd = object->add_subcommand("gallery", "render every category (seed 1) half open into one PNG");
  gallery_cmd->add_option("--out", png, "PNG file")->capture_default_str();
  gallery_cmd->add_option("--size", size, "pixels per picture")->check(CLI::PositiveNumber)->capture_default_str();
  gallery_cmd->add_option("--columns", columns, "pictures per row")->check(CLI::PositiveNumber)->capture_default_str();
  out.push_back({gallery_cmd, [] { return gallery(png, size, columns); }, false});
}

}  // namespace bimart::cli
