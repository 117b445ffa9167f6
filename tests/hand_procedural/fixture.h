// The procedural hands, generated once per test program (about 3 s each).
#pragma once

#include "core/hand/procedural_hand.h"

namespace bimart::test {

inline const HandModel& right_hand() {
  static const HandModel m = make_procedural_hand(HandSide::Right);
  return m;
}
inline const HandModel& left_hand() {
  static const HandModel m = make_procedural_hand(HandSide::Left);
  return m;
}

}  // namespace bimart::test
