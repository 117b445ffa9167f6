// The object a trajectory runs on: named by the stage (its `object` or `category` + `seed`
// parameters) or else by the trajectory file. A path is an object folder or YAML (`bimart
// object make`, `bimart object import`) or an ARCTIC template folder, relative to the
// trajectory file's folder unless absolute. A procedural object is made from its category
// and seed and written to a folder, so that exporters can refer to it by path.
#pragma once

#include <string>

#include <Eigen/Geometry>

#include "core/object/articulated_object.h"
#include "core/trajectory/trajectory.h"

namespace bimart {

struct TrajectoryObject {
  ArticulatedObject object;
  std::string path;     // absolute: the object's folder or YAML (for a procedural object: where it goes)
  bool procedural = false;  // path still to be written with save_trajectory_object
  // Set by make_canonical: the move from the source object's frame to the canonical one, and
  // whether `path` is a canonical copy still to be written with save_trajectory_object.
  Eigen::Isometry3d from_source = Eigen::Isometry3d::Identity();
  bool moved = false;
  bool canonical_copy = false;
};

// The object moved to its canonical pose about the hinge (core/object/canonical_frame.h),
// as every model expects it, when it is not there already. States given for the source are
// then moved with canonical_states(states, from_source), object-frame points with
// from_source; `path` becomes the canonical copy's folder in the cache (a procedural object
// keeps its own), so that a sequence that names the object by path names the object its
// states are for. The world geometry of every frame is unchanged.
void make_canonical(TrajectoryObject& object);

// `chosen` (the stage's parameters) wins over `from_file`; with neither, an error naming
// the file. `object_dir` is where a procedural object goes ("" = default_object_dir()).
TrajectoryObject resolve_trajectory_object(const ObjectReference& chosen, const ObjectReference& from_file,
                                           const std::string& trajectory_file, const std::string& object_dir);

// Writes a procedural object or a canonical copy to its path (each file atomically; the same
// category and seed, or the same source, always write the same files). Does nothing for
// other objects.
void save_trajectory_object(const TrajectoryObject& object);

// $BIMART_CACHE_DIR, else $XDG_CACHE_HOME/bimart, else ~/.cache/bimart, else the temp
// folder's bimart-cache; plus /objects/<category>_<seed>.
std::string default_object_dir(const std::string& category, std::int64_t seed);

// The cache folder of a canonical copy: .../objects/canonical/<name>_<fingerprint of its meshes>.
std::string canonical_object_dir(const ArticulatedObject& canonical);

}  // namespace bimart
