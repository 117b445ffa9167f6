#include "core/object/families/families.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/object/families/primitives.h"
#include "core/util/error.h"
#include "core/util/text.h"

namespace bimart {

namespace {

using Eigen::Vector3d;
using shapes::append;
using shapes::capsule;
using shapes::rounded_box;
using shapes::rounded_cylinder;
using shapes::torus;

constexpr double kDeg = M_PI / 180.0;

// Dimension lookup that names the missing key (a bug in the table, not a user error).
struct Dims {
  const Dimensions& d;
  double operator()(const char* name) const {
    auto it = d.find(name);
    if (it == d.end()) throw Error(std::string("object family: dimension '") + name + "' is not in the table");
    return it->second;
  }
};

// Builders: each writes the closed (angle 0) object in the canonical frame of families.h.

void build_box(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), D = d("depth"), H = d("height"), T = d("lid_thickness");
  bottom = rounded_box(Vector3d(-D, -H, -W / 2), Vector3d(0, 0, W / 2), 0.004, s);
  top = rounded_box(Vector3d(-D, 0, -W / 2), Vector3d(0, T, W / 2), 0.003, s);
  // A tab at the front edge of the lid to lift it by.
  append(top, rounded_box(Vector3d(-D - 0.02, 0.0, -0.025), Vector3d(-D, 0.5 * T, 0.025), 0.002, s));
}

void build_laptop(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), D = d("depth"), Tb = d("base_thickness"), Tl = d("lid_thickness");
  bottom = rounded_box(Vector3d(-D, -Tb, -W / 2), Vector3d(0, 0, W / 2), 0.35 * Tb, s);
  top = rounded_box(Vector3d(-D, 0, -W / 2), Vector3d(0, Tl, W / 2), 0.4 * Tl, s);
}

void build_notebook(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), D = d("depth"), Tp = d("pages_thickness"), Tc = d("cover_thickness");
  bottom = rounded_box(Vector3d(-D, -Tp - Tc, -W / 2), Vector3d(0, 0, W / 2), 0.4 * Tc, s);
  top = rounded_box(Vector3d(-D, 0, -W / 2), Vector3d(0, Tc, W / 2), 0.4 * Tc, s);
}

void build_microwave(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), P = d("depth"), H = d("height"), Td = d("door_thickness");
  // Body: x in [-W, 0], depth along -y from the front face y = 0, height along z.
  bottom = rounded_box(Vector3d(-W, -P, -H / 2), Vector3d(0, 0, H / 2), 0.012, s);
  // Door hinged at the front edge x = 0, covering three quarters of the front; control
  // panel is the rest. Handle near the door's free edge.
  const double door = 0.75 * W;
  top = rounded_box(Vector3d(-door, 0, -H / 2 + 0.012), Vector3d(0, Td, H / 2 - 0.012), 0.006, s);
  append(top, rounded_box(Vector3d(-door + 0.02, Td, -0.3 * H), Vector3d(-door + 0.045, Td + 0.028, 0.3 * H), 0.008, s));
}

void build_waffleiron(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), Hb = d("base_height"), Hl = d("lid_height"), Lh = d("handle_length");
  bottom = rounded_box(Vector3d(-W, -Hb, -W / 2), Vector3d(0, 0, W / 2), 0.012, s);
  append(bottom, rounded_box(Vector3d(-W - Lh, -0.65 * Hb, -0.03), Vector3d(-W, -0.3 * Hb, 0.03), 0.006, s));
  // A round lid on the square base and a handle at the front.
  const double R = 0.47 * W;
  top = rounded_cylinder(Vector3d(-W / 2, Hl / 2, 0), 1, R, Hl, 0.4 * Hl, s);
  append(top, rounded_box(Vector3d(-W - Lh, 0.25 * Hl, -0.03), Vector3d(-W / 2 - R + 0.004, 0.6 * Hl, 0.03), 0.006, s));
}

void build_capsulemachine(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), D = d("depth"), H = d("height"), L = d("lid_length");
  bottom = rounded_box(Vector3d(-D, -H, -W / 2), Vector3d(0, 0, W / 2), 0.012, s);
  // Drip tray in front of the body.
  append(bottom, rounded_box(Vector3d(-D - 0.07, -H, -0.4 * W), Vector3d(-D, -H + 0.025, 0.4 * W), 0.006, s));
  // The lid lever: a plate on top from the back hinge, and a round bar at its front.
  top = rounded_box(Vector3d(-L, 0, -W / 2 + 0.008), Vector3d(0, 0.025, W / 2 - 0.008), 0.008, s);
  append(top, capsule(Vector3d(-L - 0.012, 0.014, 0), 2, 0.012, 0.8 * W, s));
}

void build_espressomachine(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), D = d("depth"), H = d("height"), L = d("lever_length");
  // Body top at y = -0.035; a pedestal carries the lever's hub at the origin.
  bottom = rounded_box(Vector3d(-D, -0.035 - H, -W / 2), Vector3d(0.0, -0.035, W / 2), 0.015, s);
  append(bottom, rounded_box(Vector3d(-0.03, -0.035, -0.028), Vector3d(0.02, -0.021, 0.028), 0.004, s));
  // Group head under the front of the body.
  append(bottom, rounded_cylinder(Vector3d(-0.75 * D, -0.035 - 0.45 * H, 0), 1, 0.035, 0.06, 0.008, s));
  // Lever: hub around the hinge, an arm towards -x and a knob; finer, as hands hold it.
  const double f = 0.5 * s;
  top = rounded_cylinder(Vector3d(0, 0, 0), 2, 0.018, 0.045, 0.004, f);
  append(top, capsule(Vector3d(-(L + 0.016) / 2, 0, 0), 0, 0.009, L - 0.016, f));
  append(top, capsule(Vector3d(-L - 0.01, 0, 0), 0, 0.018, 0.045, f));
}

void build_mixer(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double L = d("base_length"), W = d("base_width"), Hc = d("column_height"), Lh = d("head_length"),
               R = d("head_radius");
  const double Hb = 0.04;
  // Column at the back (x in [-0.09, 0]) on a base plate; the head pivots on the column.
  bottom = rounded_box(Vector3d(-0.09, -Hc, -0.05), Vector3d(0, -0.002, 0.05), 0.015, s);
  append(bottom, rounded_box(Vector3d(-L, -Hc - Hb, -W / 2), Vector3d(0.02, -Hc, W / 2), 0.015, s));
  top = capsule(Vector3d(-Lh / 2, R, 0), 0, R, Lh, s);
  // The beater shaft and paddle below the front of the head.
  append(top, rounded_cylinder(Vector3d(-0.65 * Lh, -0.03, 0), 1, 0.008, 0.07, 0.003, s));
  append(top, rounded_box(Vector3d(-0.65 * Lh - 0.03, -0.12, -0.006), Vector3d(-0.65 * Lh + 0.03, -0.065, 0.006),
                          0.004, s));
}

void build_ketchup(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double R = d("body_radius"), Hb = d("body_height"), Rc = d("cap_radius"), Hn = d("neck_height"),
               Hc = d("cap_height");
  // Bottle along y, centred on x = -Rc so that the cap's back edge is on the hinge.
  bottom = rounded_cylinder(Vector3d(-Rc, -Hn - Hb / 2, 0), 1, R, Hb, 0.45 * R, s);
  append(bottom, rounded_cylinder(Vector3d(-Rc, -Hn / 2, 0), 1, Rc, Hn, 0.002, s));
  // The cap and the lip to flip it open with; finer, as a thumb pushes it.
  const double f = 0.5 * s;
  top = rounded_cylinder(Vector3d(-Rc, Hc / 2, 0), 1, Rc, Hc, 0.3 * Hc, f);
  append(top, rounded_box(Vector3d(-2 * Rc - 0.006, 0.5 * Hc, -0.006), Vector3d(-2 * Rc + 0.001, 0.85 * Hc, 0.006),
                          0.0015, f));
}

void build_phone(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double W = d("width"), L = d("half_length"), T = d("thickness");
  bottom = rounded_box(Vector3d(-L, -T, -W / 2), Vector3d(0, 0, W / 2), 0.3 * T, s);
  top = rounded_box(Vector3d(-L, 0, -W / 2), Vector3d(0, T, W / 2), 0.3 * T, s);
}

void build_scissors(const Dimensions& dd, double s, TriangleMesh& top, TriangleMesh& bottom) {
  const Dims d{dd};
  const double Lb = d("blade_length"), Lh = d("handle_length"), Wb = d("blade_width"), T = d("thickness"),
               Rr = d("ring_radius");
  const double tube = 0.003;
  // Blades along +x, handles along -x, in the plane z = 0: the bottom blade below it, the
  // top blade above it; opening turns the top blade towards -y and its handle towards +y.
  for (int part = 0; part < 2; ++part) {
    const double z0 = part == 0 ? -T : 0.0, z1 = part == 0 ? 0.0 : T, zr = part == 0 ? -tube : tube;
    const double side = part == 0 ? -1.0 : 1.0;  // rings sit on either side of the x axis
    TriangleMesh m = rounded_box(Vector3d(-0.008, -Wb / 2, z0), Vector3d(Lb, Wb / 2, z1), 0.4 * T, s);
    append(m, rounded_box(Vector3d(-Lh, side > 0 ? 0.0 : -0.006, z0), Vector3d(-0.008, side > 0 ? 0.006 : 0.0, z1),
                          0.4 * T, s));
    append(m, torus(Vector3d(-Lh - Rr + tube, side * Rr * 0.5, zr), 2, Rr - tube, tube, s));
    (part == 0 ? bottom : top) = std::move(m);
  }
}

std::vector<ObjectFamily> make_table() {
  // name, description, dimensions {name, min, max, what}, limits, open angle, detail, builder
  return {
      {"box", "cardboard box with a hinged lid",
       {{"width", 0.15, 0.35, "side along the hinge"},
        {"depth", 0.12, 0.30, "side away from the hinge"},
        {"height", 0.08, 0.20, "height of the box"},
        {"lid_thickness", 0.008, 0.02, "thickness of the lid"}},
       0.0, 110 * kDeg, 70 * kDeg, 17, build_box},
      {"laptop", "laptop: base and screen lid",
       {{"width", 0.28, 0.38, "side along the hinge"},
        {"depth", 0.19, 0.26, "side away from the hinge"},
        {"base_thickness", 0.012, 0.022, "base (keyboard) thickness"},
        {"lid_thickness", 0.005, 0.010, "screen lid thickness"}},
       0.0, 135 * kDeg, 100 * kDeg, 23, build_laptop},
      {"notebook", "paper notebook: page block with back cover, and front cover",
       {{"width", 0.15, 0.22, "along the spine"},
        {"depth", 0.21, 0.30, "away from the spine"},
        {"pages_thickness", 0.006, 0.02, "page block"},
        {"cover_thickness", 0.0015, 0.003, "front cover"}},
       0.0, 175 * kDeg, 90 * kDeg, 23, build_notebook},
      {"microwave", "microwave oven with a side-hinged door (stands along z)",
       {{"width", 0.42, 0.55, "front width (x)"},
        {"depth", 0.30, 0.42, "front to back (y)"},
        {"height", 0.24, 0.32, "height (z)"},
        {"door_thickness", 0.02, 0.035, "door"}},
       0.0, 100 * kDeg, 70 * kDeg, 21, build_microwave},
      {"waffleiron", "waffle iron: square base with handle, round lid with handle",
       {{"width", 0.22, 0.30, "square base side"},
        {"base_height", 0.04, 0.07, "base height"},
        {"lid_height", 0.035, 0.06, "lid height"},
        {"handle_length", 0.05, 0.09, "handles, beyond the front"}},
       0.0, 100 * kDeg, 60 * kDeg, 20, build_waffleiron},
      {"capsulemachine", "capsule coffee machine with a lid lever on top",
       {{"width", 0.10, 0.16, "side along the hinge"},
        {"depth", 0.22, 0.32, "front to back"},
        {"height", 0.20, 0.30, "body height"},
        {"lid_length", 0.08, 0.13, "lever plate length"}},
       0.0, 90 * kDeg, 60 * kDeg, 21, build_capsulemachine},
      {"espressomachine", "espresso machine with a lever on a hub",
       {{"width", 0.14, 0.22, "side along the hinge"},
        {"depth", 0.25, 0.35, "front to back"},
        {"height", 0.28, 0.38, "body height"},
        {"lever_length", 0.12, 0.20, "lever arm"}},
       0.0, 80 * kDeg, 50 * kDeg, 22, build_espressomachine},
      {"mixer", "stand mixer with a tilting head",
       {{"base_length", 0.25, 0.35, "base plate length"},
        {"base_width", 0.16, 0.22, "base plate width"},
        {"column_height", 0.18, 0.26, "column height"},
        {"head_length", 0.25, 0.34, "head length"},
        {"head_radius", 0.05, 0.07, "head radius"}},
       0.0, 65 * kDeg, 45 * kDeg, 22, build_mixer},
      {"ketchup", "squeeze bottle with a flip cap",
       {{"body_radius", 0.028, 0.04, "bottle radius"},
        {"body_height", 0.12, 0.18, "bottle height"},
        {"cap_radius", 0.014, 0.02, "cap radius"},
        {"neck_height", 0.018, 0.028, "neck below the cap"},
        {"cap_height", 0.012, 0.018, "flip cap height"}},
       0.0, 140 * kDeg, 100 * kDeg, 26, build_ketchup},
      {"phone", "flip phone: two halves",
       {{"width", 0.045, 0.055, "along the hinge"},
        {"half_length", 0.085, 0.105, "each half"},
        {"thickness", 0.008, 0.012, "each half"}},
       0.0, 165 * kDeg, 150 * kDeg, 26, build_phone},
      {"scissors", "scissors: two blades with ring handles, pivot on the hinge",
       {{"blade_length", 0.07, 0.11, "blade beyond the pivot"},
        {"handle_length", 0.04, 0.06, "handle arm before the ring"},
        {"blade_width", 0.012, 0.018, "blade width"},
        {"thickness", 0.0015, 0.0025, "blade thickness"},
        {"ring_radius", 0.012, 0.018, "finger ring outer radius"}},
       0.0, 60 * kDeg, 35 * kDeg, 20, build_scissors},
  };
}

double unit_uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);  // 53 bits in [0, 1)
}

}  // namespace

const std::vector<ObjectFamily>& object_families() {
  static const std::vector<ObjectFamily> table = make_table();
  return table;
}

std::vector<std::string> object_categories() {
  std::vector<std::string> names;
  for (const auto& f : object_families()) names.push_back(f.name);
  return names;
}

const ObjectFamily& object_family(const std::string& category) {
  for (const auto& f : object_families())
    if (f.name == category) return f;
  throw Error("unknown object category '" + category + "'" + did_you_mean(category, object_categories()) +
              "; categories: " + join(object_categories(), ", "));
}

Dimensions sample_dimensions(const ObjectFamily& family, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Dimensions d;
  for (const auto& r : family.dimensions) d[r.name] = r.min + (r.max - r.min) * unit_uniform(rng);
  return d;
}

ArticulatedObject make_object(const std::string& category, const Dimensions& dims, const std::string& name) {
  const ObjectFamily& f = object_family(category);
  Dimensions d = dims;
  double largest = 0;
  for (const auto& r : f.dimensions) {
    d.try_emplace(r.name, 0.5 * (r.min + r.max));
    largest = std::max(largest, d[r.name]);
  }
  ArticulatedObject o;
  o.name = name;
  o.category = f.name;
  f.build(d, largest / f.detail, o.top, o.bottom);
  o.angle_min = f.angle_min;
  o.angle_max = f.angle_max;
  o.open_angle = f.open_angle;
  o.units_note = "procedural (m)";
  return o;
}

ArticulatedObject make_object(const std::string& category, std::uint64_t seed) {
  const ObjectFamily& f = object_family(category);
  return make_object(category, sample_dimensions(f, seed), f.name + "_" + std::to_string(seed));
}

}  // namespace bimart
