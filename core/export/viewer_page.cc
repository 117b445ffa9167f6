#include "core/export/viewer_page.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/features/contact_map.h"
#include "core/hand/lbs.h"
#include "core/object/object_state.h"
#include "core/util/atomic_file.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart {
namespace {

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// Text safe inside <script>: no "</" sequence can end the element early.
std::string script_safe(std::string s) {
  for (size_t p = s.find("</"); p != std::string::npos; p = s.find("</", p + 3)) s.replace(p, 2, "<\\/");
  return s;
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

constexpr const char* kStyle = R"(
html, body { margin: 0; height: 100%; font: 14px system-ui, sans-serif; background: #f4f4f6; color: #222; }
#view { position: absolute; top: 44px; left: 0; width: 100%; height: calc(100% - 44px); display: block; }
#bar { height: 44px; display: flex; align-items: center; gap: 8px; padding: 0 8px; font-size: 13px; background: #fff;
       border-bottom: 1px solid #ccc; white-space: nowrap; overflow-x: auto; }
#slider { flex: 1; min-width: 80px; }
#frame { font-variant-numeric: tabular-nums; min-width: 8em; }
#status { color: #a00; }
#marks { position: absolute; top: 44px; left: 0; width: 100%; height: 34px; background: #fff; border-bottom: 1px solid #ccc;
         font-size: 12px; }
#timeline { position: absolute; left: 8px; top: 3px; width: calc(100% - 16px); height: 14px; }
#now { position: absolute; left: 8px; top: 18px; white-space: nowrap; overflow: hidden; width: calc(100% - 16px); }
body.directed #view { top: 79px; height: calc(100% - 79px); }
.key { display: inline-block; width: 10px; height: 10px; border-radius: 2px; margin-right: 3px; }
)";

}  // namespace

std::vector<std::vector<std::pair<std::int64_t, int>>> viewer_contacts(const Sequence& s) {
  std::vector<std::vector<std::pair<std::int64_t, int>>> out;
  if (!s.contact_maps.defined() || !s.basis_hit_indices.defined()) return out;
  const at::Tensor c = s.contact_maps.to(at::kFloat).contiguous();
  const at::Tensor ids = s.basis_hit_indices.to(at::kLong).contiguous();
  const std::int64_t n = c.size(0), k = c.size(2);
  out.resize(n);
  const float* cp = c.data_ptr<float>();
  const std::int64_t* ip = ids.data_ptr<std::int64_t>();
  for (std::int64_t t = 0; t < n; ++t)
    for (int h = 0; h < 2; ++h)
      for (std::int64_t j = 0; j < k; ++j)
        if (cp[(t * 2 + h) * k + j] < kViewerContactDistance) out[t].emplace_back(ip[t * k + j], h);
  return out;
}

std::vector<std::vector<std::pair<std::int64_t, int>>> measured_contacts(const SceneSource& src) {
  const Sequence& s = src.sequence;
  const std::int64_t n = s.num_frames(), vt = src.object.top.num_vertices(), vb = src.object.bottom.num_vertices();
  const int vh = src.models()[0]->num_vertices();
  at::Tensor objp = at::empty({n, vt + vb, 3}, at::kDouble), hands = at::empty({2, n, vh, 3}, at::kDouble);
  const at::Tensor states = s.object_states.to(at::kDouble).contiguous();
  for (std::int64_t t = 0; t < n; ++t) {
    const PosedObject o = pose_world(src.object, ObjectState::from_row(states[t].data_ptr<double>()));
    double* op = objp[t].data_ptr<double>();
    std::copy(o.top.data(), o.top.data() + o.top.size(), op);
    std::copy(o.bottom.data(), o.bottom.data() + o.bottom.size(), op + o.top.size());
    for (int h = 0; h < 2; ++h) {
      const HandParams& p = s.hands.hands[h];
      const at::Tensor rot = p.rot[t].to(at::kDouble).contiguous(), pose = p.pose[t].to(at::kDouble).contiguous(),
                       trans = p.trans[t].to(at::kDouble).contiguous(), beta = p.shape.to(at::kDouble).contiguous();
      LbsResult<double> r;
      lbs(*src.models()[h], rot.data_ptr<double>(), pose.data_ptr<double>(), trans.data_ptr<double>(),
          beta.data_ptr<double>(), &r);
      std::copy(r.vertices.data(), r.vertices.data() + r.vertices.size(), hands[h][t].data_ptr<double>());
    }
  }
  const at::Tensor c = contact_maps(objp, hands).contiguous();  // [N, 2, Vt + Vb]
  const double* cp = c.data_ptr<double>();
  std::vector<std::vector<std::pair<std::int64_t, int>>> out(n);
  for (std::int64_t t = 0; t < n; ++t)
    for (int h = 0; h < 2; ++h)
      for (std::int64_t v = 0; v < vt + vb; ++v)
        if (cp[(t * 2 + h) * (vt + vb) + v] < kViewerContactDistance) out[t].emplace_back(v, h);
  return out;
}

std::string viewer_bundle_path() {
  try {
    return find_data_file("viewer/viewer_bundle.js");
  } catch (const Error& e) {
    throw Error(std::string("the viewer script (three.js bundle) is missing: build it with "
                            "`cmake --build build --target viewer_bundle` (needs npm and the npm registry once; "
                            "docs/outputs.md). ") + e.what());
  }
}

std::string viewer_page(const std::vector<ViewerSample>& samples, const std::string& title, const std::string& bundle) {
  if (samples.empty()) throw Error("viewer page: no samples");
  nlohmann::json data;
  data["title"] = title;
  for (const ViewerSample& s : samples) {
    nlohmann::json j{{"name", s.name}, {"fps", s.fps}, {"frames", s.frames}, {"glb", base64(s.glb)}};
    if (!s.contacts.empty()) {
      nlohmann::json frames = nlohmann::json::array();
      for (const auto& f : s.contacts) {
        nlohmann::json row = nlohmann::json::array();
        for (const auto& [v, h] : f) {
          row.push_back(v);
          row.push_back(h);
        }
        frames.push_back(std::move(row));
      }
      j["contacts"] = {{"top", s.top_vertices}, {"frames", std::move(frames)}};
    }
    for (const ViewerMark& m : s.marks) {
      nlohmann::json mj{{"hand", m.hand}, {"first", m.first}, {"last", m.last}, {"kind", m.kind}, {"label", m.label}};
      if (!m.wrists.empty()) mj["wrists"] = m.wrists;
      if (m.region_point) mj["region"] = {{"point", *m.region_point}, {"radius", m.region_radius}, {"part", m.region_part}};
      j["marks"].push_back(std::move(mj));
    }
    data["samples"].push_back(std::move(j));
  }
  std::ostringstream html;
  html << "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       << "<title>" << html_escape(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n"
       << "<div id=\"bar\"><button id=\"play\">Pause</button>"
       << "<input id=\"slider\" type=\"range\" min=\"0\" max=\"0\" value=\"0\"><span id=\"frame\">frame 0</span>"
       << "<label>speed <select id=\"speed\"><option>0.25</option><option>0.5</option>"
       << "<option selected>1</option><option>2</option></select></label>"
       << "<label>sample <select id=\"sample\"></select></label>"
       << "<label><input id=\"show-left\" type=\"checkbox\" checked>left</label>"
       << "<label><input id=\"show-right\" type=\"checkbox\" checked>right</label>"
       << "<label><input id=\"show-object\" type=\"checkbox\" checked>object</label>"
       << "<label title=\"object points within 5 mm of a hand, from the sequence's contact map\">"
       << "<input id=\"show-contacts\" type=\"checkbox\" checked>contacts "
       << "<span class=\"key\" style=\"background:#e60d0d\"></span>left "
       << "<span class=\"key\" style=\"background:#8c0dd9\"></span>right</label>"
       << "<span id=\"status\">loading…</span></div>\n"
       << "<div id=\"marks\" hidden><canvas id=\"timeline\"></canvas><span id=\"now\"></span></div>\n"
       << "<canvas id=\"view\"></canvas>\n"
       << "<script type=\"application/json\" id=\"bimart-data\">" << script_safe(data.dump()) << "</script>\n"
       << "<script>\n" << script_safe(bundle) << "\n</script>\n</body>\n</html>\n";
  return html.str();
}

std::uintmax_t write_viewer_page(const std::vector<ViewerSample>& samples, const std::string& title,
                                 const std::string& path) {
  const std::string bundle_path = viewer_bundle_path();
  std::ifstream in(bundle_path, std::ios::binary);
  std::stringstream bundle;
  bundle << in.rdbuf();
  if (!in || bundle.str().empty()) throw Error("cannot read the viewer script " + bundle_path);
  const std::string page = viewer_page(samples, title, bundle.str());
  write_file_atomically(path, [&](std::ostream& out) { out.write(page.data(), static_cast<std::streamsize>(page.size())); });
  return page.size();
}

}  // namespace bimart
