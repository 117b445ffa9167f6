// Hand constraints (core/directing/hand_constraints.h) as the refinement keeps them
// (RefineDirections, core/refine/refinement.h): wrist pins as they are; a pose pin as the
// wrist, orientation and finger pose of the sample's hand at its frame, carried with the
// object from that frame to the pinned one; `none` as a clearance; the hands that may hold.
#pragma once

#include <array>

#include <ATen/core/Tensor.h>

#include "core/directing/hand_constraints.h"
#include "core/hand/hand_model.h"
#include "core/refine/refinement.h"

namespace bimart {

// states [N, 7]: the run's object states.
RefineDirections refine_directions(const HandConstraints& constraints, const std::array<const HandModel*, 2>& hands,
                                   const at::Tensor& states);

// The pins alone, cut to the frames of `states`, as the refinement pins them (per hand, per
// frame: wrist, orientation, fingers): what a sample is measured against (viewer marks, the
// constraint report). `pins` gets the cut ranges.
RefineDirections pinned_targets(std::vector<HandPin>& pins, const std::array<const HandModel*, 2>& hands,
                                const at::Tensor& states);

}  // namespace bimart
