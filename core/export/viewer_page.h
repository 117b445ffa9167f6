// The viewer page (docs/outputs.md): one self-contained HTML file that plays one or more
// samples from disk with no network. Each sample is a .glb (core/export/gltf_scene.h)
// embedded as base64, played by the bundled three.js, plus an optional per-frame contact
// highlight on the object.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/export/scene_source.h"
#include "core/export/viewer_marks.h"
#include "core/io/sequence.h"

namespace bimart {

// Contacts within this distance (m) of a hand are highlighted (issue 14).
inline constexpr double kViewerContactDistance = 0.005;

struct ViewerSample {
  std::string name;
  double fps = 30;
  std::int64_t frames = 0;
  std::string glb;  // the scene's bytes
  // Per frame, the object vertices (ids into [top; bottom]) within kViewerContactDistance of
  // a hand, with that hand (0 left, 1 right); empty when the sequence holds no contact map.
  std::vector<std::vector<std::pair<std::int64_t, int>>> contacts;
  std::int64_t top_vertices = 0;  // to split the ids into top and bottom
  std::vector<ViewerMark> marks;   // a directed run's constraints (core/export/viewer_marks.h)
};

// A sample's contacts from the sequence's `contact_maps` and `basis_hit_indices` (none when
// it has no contact map): entries below kViewerContactDistance.
std::vector<std::vector<std::pair<std::int64_t, int>>> viewer_contacts(const Sequence& sequence);

// Contacts measured from the posed hands instead (for sequences without a contact map, e.g.
// ground truth): every object vertex within kViewerContactDistance of a hand vertex.
std::vector<std::vector<std::pair<std::int64_t, int>>> measured_contacts(const SceneSource& source);

// The path of the bundled viewer script (three.js and the viewer, built by
// core/export/viewer/build_bundle.sh). Throws bimart::Error saying how to build it.
std::string viewer_bundle_path();

// The page. `bundle` is the script's text.
std::string viewer_page(const std::vector<ViewerSample>& samples, const std::string& title, const std::string& bundle);

// Reads the bundle, builds the page and writes it atomically; returns its size in bytes.
std::uintmax_t write_viewer_page(const std::vector<ViewerSample>& samples, const std::string& title,
                                 const std::string& path);

}  // namespace bimart
