// Hand model files (core/hand/hand_model.cc) and the keypoint rule every command applies.
#include "core/hand/hand_model.h"
#include "core/hand/keypoints.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bimart::fuzz::input_file(data, size, ".npz");
  bimart::fuzz::only_bimart_errors([&] {
    const bimart::HandModel m = bimart::load_hand_model(path);
    if (!m.keypoints.empty()) bimart::model_keypoints(m);
  });
  return 0;
}
