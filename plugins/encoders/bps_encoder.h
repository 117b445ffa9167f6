// The three BPS encoders share everything but the variant: this class does the work,
// u_bps.cc, npa_bps.cc and np_bps.cc name and register one variant each.
#pragma once

#include <ATen/ATen.h>

#include "core/data/window_dataset.h"  // bps_variant_name
#include "core/features/bps.h"
#include "core/util/data_path.h"
#include "stages/object_encoder.h"

namespace bimart {

template <BpsVariant V>
class BpsEncoder : public ObjectEncoder {
 public:
  static StageSpec make_spec(const char* name, const char* help) {
    return StageSpec::of<ObjectEncoder>(name, help)
        .param("basis", default_basis_file(V),
               "BPS basis file (.npz); relative paths are looked up in the data folders");
  }

  explicit BpsEncoder(const Params& p) : basis_(load_bps_basis(find_data_file(p.string("basis")))) {
    if (basis_.points.rows() != basis_size(V))
      throw Error(p.string("basis") + " holds " + std::to_string(basis_.points.rows()) +
                  " basis points; this encoder needs " + std::to_string(basis_size(V)));
  }

  void run(StageIO& io) override {
    ObjectEncoding e = encode_object(io.in<ArticulatedObject>("object"), io.in<at::Tensor>("object_states"),
                                     basis_, V);
    io.out("object_features", e.features);
    io.out("global_states", e.global_states);
    io.out("object_scale", e.scale);
    io.out("basis_hit_indices", e.hit_indices);
    io.out("basis_points", e.basis_points);
    io.out("encoder_variant", bps_variant_name(V));
  }

 private:
  BpsBasis basis_;
};

}  // namespace bimart
