// bimart object make | list | info | gallery: procedural objects, object files, a picture of all
// categories.
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <map>
#include <tuple>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/object/families/families.h"
#include "core/object/mesh_repair.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"
#include "core/render/rasterizer.h"
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
