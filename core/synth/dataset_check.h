// The data issue's checks of a data set beyond the paper's metrics (docs/data.md): both hands
// touching while the object moves, which hand drives use sequences, and how deep the two
// hands ever interpenetrate. `bimart data check` prints them; they work on any data set
// folder (synthetic or converted ARCTIC).
#pragma once

#include <cstdint>
#include <string>

namespace bimart {

struct DatasetCheck {
  int sequences = 0;
  std::int64_t moving_frames = 0;     // frames t where the object moves (as Con counts them)
  std::int64_t both_touching = 0;     // ... where both hands have a vertex within 5 mm of it
  int use_sequences = 0;              // sequences of kind "use" whose hinge moves
  int left_drives = 0;                // ... where the left hand touches the top part more often
  double hand_interpenetration = 0;   // deepest vertex of one hand inside the other (m)
  std::string deepest_sequence;       // where that was
};

// Every `frame_step`-th frame is used for the hand–hand depth (a tree per hand and frame).
// Hands are posed with `mano_left`/`mano_right` when given (both), else the shipped models.
DatasetCheck check_dataset(const std::string& folder, const std::string& split, int threads = 0,
                           bool progress = false, int frame_step = 2, const std::string& mano_left = "",
                           const std::string& mano_right = "");

}  // namespace bimart
