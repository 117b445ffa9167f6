// Per-frame trajectory in CSV (docs/trajectories.md, "CSV"): a header naming the seven
// columns angle, rx, ry, rz, tx, ty, tz (any order; optional `frame`, ignored, and `time` in
// seconds, evenly spaced, which gives the frame rate), one row per frame (rad, m). Lines
// starting with '#' are comments; `# fps: 60`, `# object: PATH`, `# category: NAME` and
// `# seed: N` set the frame rate and the object. export.states_csv writes this format.
#pragma once

#include <string>

#include "core/trajectory/trajectory.h"

namespace bimart {

// fps is 0 when the file gives none. Throws bimart::Error "file:line: ..." on any fault.
Trajectory read_csv_trajectory(const std::string& path);

}  // namespace bimart
