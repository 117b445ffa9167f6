#include "core/trajectory/yaml_trajectory.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/trajectory/keyframes.h"
#include "core/trajectory/validation.h"
#include "core/trajectory/yaml_reader.h"
#include "core/util/yaml_keys.h"

namespace bimart {

namespace {

constexpr double kDeg = M_PI / 180.0;

struct Reader : YamlReader {
  std::int64_t seed(const YAML::Node& n) const {
    const double s = number(n, "seed");
    if (s < 0 || s != std::floor(s) || s > 1e15) throw Error(at(n), "seed must be a whole number >= 0");
    return static_cast<std::int64_t>(s);
  }

  // `object: PATH` or `object: {path: PATH}` or `object: {category: NAME, seed: N}`.
  ObjectReference object(const YAML::Node& n) const {
    ObjectReference r;
    r.where = at(n);
    if (n.IsScalar()) {
      r.path = n.Scalar();
    } else if (n.IsMap()) {
      check_known_keys(n, {"path", "category", "seed"}, file, "object");
      if (n["path"]) r.path = text(n["path"], "object.path");
      if (n["category"]) r.category = text(n["category"], "object.category");
      if (n["seed"]) r.seed = seed(n["seed"]);
      if (r.path.empty() == r.category.empty())
        throw Error(r.where, "object must give either path or category (with seed)");
      if (!r.path.empty() && n["seed"]) throw Error(at(n["seed"]), "seed goes with category, not with path");
    } else {
      throw Error(r.where, "object must be a path or a map {category: NAME, seed: N}");
    }
    if (r.path.empty() && r.category.empty()) throw Error(r.where, "object is empty");
    return r;
  }

  Keyframe key(const YAML::Node& n) const {
    if (!n.IsMap()) throw Error(at(n), "each key must be a map with t and any of position, rotation, angle");
    check_known_keys(n, {"t", "position", "rotation", "angle"}, file, "a key");
    Keyframe k;
    k.line = at(n).line;
    if (!n["t"]) throw Error(at(n), "this key has no time t (seconds)");
    k.t = number(n["t"], "t");
    if (n["position"]) k.position = vec3(n["position"], "position");
    if (n["rotation"]) k.rotation = rotation(n["rotation"]);
    if (n["angle"]) k.angle = number(n["angle"], "angle") * kDeg;
    if (!k.position && !k.rotation && !k.angle) throw Error(at(n), "this key gives none of position, rotation, angle");
    return k;
  }
};

}  // namespace

Trajectory read_yaml_trajectory(const std::string& path, double fps) {
  std::string source;
  {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open the trajectory file");
    std::stringstream ss;
    ss << in.rdbuf();
    source = ss.str();
  }
  YAML::Node root;
  try {
    root = YAML::Load(source);
  } catch (const YAML::ParserException& e) {
    throw Error(SourceLocation{path, e.mark.line + 1, e.mark.column + 1}, e.msg);
  }
  check_duplicate_keys(source, path);
  if (!root.IsMap()) throw Error(path + ": expected a map with `frames:` or `keys:` (docs/trajectories.md)");
  check_known_keys(root, {"name", "description", "fps", "object", "rest", "frames", "keys", "hands"}, path, "a trajectory file");
  const Reader r{{path}};
  Trajectory tr;
  tr.file = path;
  if (root["name"]) r.text(root["name"], "name");
  if (root["description"]) r.text(root["description"], "description");
  if (root["fps"]) {
    tr.fps = r.number(root["fps"], "fps");
    if (!(tr.fps > 0)) throw Error(r.at(root["fps"]), "fps must be positive");
  }
  if (root["object"]) tr.object = r.object(root["object"]);
  const YAML::Node frames = root["frames"], keys = root["keys"];
  if (frames && keys) throw Error(r.at(keys), "give either frames: (per frame) or keys: (keyframes), not both");
  if (!frames && !keys) throw Error(path + ": no `frames:` or `keys:` (docs/trajectories.md)");

  if (frames) {
    if (root["rest"]) throw Error(r.at(root["rest"]), "rest applies to keys:, not to frames:");
    if (!frames.IsSequence()) throw Error(r.at(frames), "frames must be a list of [angle, rx, ry, rz, tx, ty, tz]");
    const std::int64_t n = static_cast<std::int64_t>(frames.size());
    check_frame_count(n, r.at(frames), fmt::format("{} frames", n));
    tr.states.resize(n, 7);
    static const char* const fields[7] = {"angle", "rx", "ry", "rz", "tx", "ty", "tz"};
    for (std::int64_t f = 0; f < n; ++f) {
      const YAML::Node row = frames[static_cast<std::size_t>(f)];
      if (!row.IsSequence() || row.size() != 7)
        throw Error(r.at(row), "each frame must be a list of 7 numbers [angle, rx, ry, rz, tx, ty, tz] (rad, m)");
      for (int c = 0; c < 7; ++c) tr.states(f, c) = r.number(row[c], fields[c]);
      tr.lines.push_back({r.at(row).line, 0});
    }
    return tr;
  }

  bool rest = true;
  if (const YAML::Node n = root["rest"]) {
    try {
      rest = n.as<bool>();
    } catch (const YAML::Exception&) {
      throw Error(r.at(n), "rest must be true or false, got '" + n.Scalar() + "'");
    }
  }
  if (!keys.IsSequence()) throw Error(r.at(keys), "keys must be a list of keys (t, position, rotation, angle)");
  if (keys.size() > static_cast<std::size_t>(kMaxTrajectoryFrames))
    throw Error(r.at(keys), fmt::format("at most {} keys, got {}", kMaxTrajectoryFrames, keys.size()));
  std::vector<Keyframe> list;
  for (const YAML::Node& k : keys) list.push_back(r.key(k));
  const double file_fps = tr.fps;
  sample_keyframes(list, fps > 0 ? fps : (file_fps > 0 ? file_fps : kDefaultTrajectoryFps), rest, path, tr);
  return tr;
}

}  // namespace bimart
