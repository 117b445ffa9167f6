#include "core/data/turned_dataset.h"

#include <ATen/ATen.h>
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "core/data/manifest.h"
#include "core/geometry/rotation.h"
#include "core/io/sequence.h"
#include "core/object/object_io.h"
#include "core/util/error.h"

namespace bimart {
namespace fs = std::filesystem;

ArticulatedObject turned_object(const ArticulatedObject& object, double radians) {
  const Eigen::Matrix3d R = rotation_about(Eigen::Vector3d::UnitZ(), radians);
  ArticulatedObject o = object;
  o.top.vertices = object.top.vertices * R.transpose();
  o.bottom.vertices = object.bottom.vertices * R.transpose();
  return o;
}

ObjectState turned_state(const ObjectState& state, double radians) {
  ObjectState s = state;
  s.root_rotation = matrix_to_axis_angle(axis_angle_to_matrix(state.root_rotation) *
                                         rotation_about(Eigen::Vector3d::UnitZ(), -radians));
  return s;
}

TurnedDatasetSummary write_turned_dataset(const std::string& folder, const std::string& split,
                                          const std::vector<double>& degrees, const std::string& out, bool force) {
  if (degrees.empty()) throw Error("data turn: no angle given");
  for (double d : degrees)
    if (!std::isfinite(d)) throw Error("data turn: the angles must be finite numbers of degrees");
  if (fs::exists(fs::path(out) / "manifest.json") && !force)
    throw Error("data turn: " + out + " holds a data set already (--force replaces it)");
  const DatasetManifest in = read_manifest(folder);
  const std::vector<std::string> files = split_files(in, folder, split);
  DatasetManifest m;
  m.generator = "bimart data turn " + fs::path(folder).filename().string();
  m.seed = in.seed;
  m.fps = in.fps;
  TurnedDatasetSummary summary;
  for (double deg : degrees) {
    const double phi = deg * M_PI / 180.0;
    // One turn keeps the names; several tell the copies apart: box_05 -> box_05_t90.
    const std::string suffix = degrees.size() == 1 ? "" : fmt::format("_t{:g}", deg);
    m.generator += fmt::format(" {:g}", deg);
    std::map<std::string, std::string> written;  // source object path -> its folder in `out`
    for (const std::string& file : files) {
      Sequence s = read_sequence(file);
      const std::string object_path = fs::weakly_canonical(resolve_object_path(s, file)).string();
      auto it = written.find(object_path);
      if (it == written.end()) {
        ArticulatedObject object = turned_object(load_object(object_path), phi);
        object.name += suffix;
        const std::string rel = "objects/" + object.name;
        save_object(object, (fs::path(out) / rel).string());
        m.objects.push_back({object.name, rel, object.category, split});
        it = written.emplace(object_path, rel).first;
        ++summary.objects;
      }
      at::Tensor states = s.object_states.to(at::kDouble).contiguous();
      for (std::int64_t t = 0; t < states.size(0); ++t) {
        double* row = states.data_ptr<double>() + t * 7;
        const Eigen::Matrix<double, 7, 1> r = turned_state(ObjectState::from_row(row), phi).to_row();
        std::copy(r.data(), r.data() + 7, row);
      }
      s.object_states = states.to(s.object_states.scalar_type());
      s.name += suffix;
      const std::string rel = "sequences/" + fs::path(file).stem().string() + suffix + ".npz";
      const std::string path = (fs::path(out) / rel).string();
      fs::create_directories(fs::path(path).parent_path());
      s.object = relative_object_path((fs::path(out) / it->second).string(), path);
      write_sequence(s, path);
      (split == "train" ? m.train : m.test).push_back(rel);
      ++summary.sequences;
    }
  }
  m.generator += " deg";
  write_manifest(m, out);
  return summary;
}

}  // namespace bimart
