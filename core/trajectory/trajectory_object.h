// The object a trajectory runs on: named by the stage (its `object` or `category` + `seed`
// parameters) or else by the trajectory file. A path is an object folder or YAML (`bimart
// object make`, `bimart object import`) or an ARCTIC template folder, relative to the
// trajectory file's folder unless absolute. A procedural object is made from its category
// and seed and written to a folder, so that exporters can refer to it by path.
#pragma once

#include <string>

#include "core/object/articulated_object.h"
#include "core/trajectory/trajectory.h"

namespace bimart {

struct TrajectoryObject {
  ArticulatedObject object;
  std::string path;     // absolute: the object's folder or YAML (for a procedural object: where it goes)
  bool procedural = false;  // path still to be written with save_trajectory_object
};

// `chosen` (the stage's parameters) wins over `from_file`; with neither, an error naming
// the file. `object_dir` is where a procedural object goes ("" = default_object_dir()).
TrajectoryObject resolve_trajectory_object(const ObjectReference& chosen, const ObjectReference& from_file,
                                           const std::string& trajectory_file, const std::string& object_dir);

// Writes a procedural object to its path (each file atomically; the same category and seed
// always write the same files). Does nothing for other objects.
void save_trajectory_object(const TrajectoryObject& object);

// $BIMART_CACHE_DIR, else $XDG_CACHE_HOME/bimart, else ~/.cache/bimart, else the temp
// folder's bimart-cache; plus /objects/<category>_<seed>.
std::string default_object_dir(const std::string& category, std::int64_t seed);

}  // namespace bimart
