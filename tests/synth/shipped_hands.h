// The shipped hand models (models/hand/), loaded once per test program.
#pragma once

#include <array>

#include "core/hand/hand_model.h"
#include "core/util/data_path.h"

namespace bimart::test {

// {left, right}
inline const std::array<const HandModel*, 2>& shipped_hands() {
  static const HandModel left = load_hand_model(find_data_file("models/hand/mano_left.npz"));
  static const HandModel right = load_hand_model(find_data_file("models/hand/mano_right.npz"));
  static const std::array<const HandModel*, 2> both{&left, &right};
  return both;
}

}  // namespace bimart::test
