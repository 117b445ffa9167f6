#include "core/export/gltf_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <sstream>

#include <ATen/ATen.h>
#include <Eigen/Geometry>
#include <tiny_gltf.h>

#include "core/geometry/triangle_mesh.h"
#include "core/hand/lbs.h"
#include "core/object/object_state.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/version.h"

namespace bimart {
namespace {

constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

// One buffer, one view per accessor, every view 4-byte aligned.
class Builder {
 public:
  tinygltf::Model model;
  Builder() { model.buffers.emplace_back(); }

  int view(const void* data, size_t bytes, int target) {
    auto& buf = model.buffers[0].data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    model.bufferViews.push_back(v);
    return static_cast<int>(model.bufferViews.size()) - 1;
  }

  // `values` holds count * components floats; min/max when asked (required for POSITION,
  // animation inputs).
  int floats(const std::vector<float>& values, int type, int target, bool bounds) {
    const int comps = tinygltf::GetNumComponentsInType(type);
    tinygltf::Accessor a;
    a.bufferView = view(values.data(), values.size() * sizeof(float), target);
    a.componentType = kFloat;
    a.type = type;
    a.count = values.size() / comps;
    if (bounds) {
      a.minValues.assign(comps, std::numeric_limits<double>::infinity());
      a.maxValues.assign(comps, -std::numeric_limits<double>::infinity());
      for (size_t i = 0; i < values.size(); ++i) {
        a.minValues[i % comps] = std::min(a.minValues[i % comps], double(values[i]));
        a.maxValues[i % comps] = std::max(a.maxValues[i % comps], double(values[i]));
      }
    }
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size()) - 1;
  }

  template <class T>
  int integers(const std::vector<T>& values, int component_type, int type, int target) {
    tinygltf::Accessor a;
    a.bufferView = view(values.data(), values.size() * sizeof(T), target);
    a.componentType = component_type;
    a.type = type;
    a.count = values.size() / tinygltf::GetNumComponentsInType(type);
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size()) - 1;
  }

  int material(const std::string& name, const std::array<double, 3>& rgb, double roughness) {
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor = {rgb[0], rgb[1], rgb[2], 1.0};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = roughness;
    model.materials.push_back(m);
    return static_cast<int>(model.materials.size()) - 1;
  }

  int node(tinygltf::Node n) {
    model.nodes.push_back(std::move(n));
    return static_cast<int>(model.nodes.size()) - 1;
  }
};

std::vector<float> flat(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& m) {
  std::vector<float> out(m.size());
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (int k = 0; k < 3; ++k) out[3 * i + k] = static_cast<float>(m(i, k));
  return out;
}

// Unit normals; a vertex without faces gets +y (the validator refuses zero normals).
std::vector<float> normals(const TriangleMesh& mesh) {
  const Eigen::MatrixX3d n = vertex_normals(mesh);
  std::vector<float> out(3 * n.rows());
  for (Eigen::Index i = 0; i < n.rows(); ++i) {
    Eigen::Vector3d v = n.row(i).transpose();
    if (!(v.norm() > 0.5)) v = Eigen::Vector3d::UnitY();
    v.normalize();
    for (int k = 0; k < 3; ++k) out[3 * i + k] = static_cast<float>(v[k]);
  }
  return out;
}

std::vector<std::uint32_t> indices(const TriangleMesh& mesh) {
  std::vector<std::uint32_t> out(3 * mesh.num_faces());
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) out[3 * f + k] = static_cast<std::uint32_t>(mesh.faces(f, k));
  return out;
}

// Keeps quaternions on one hemisphere from frame to frame, so linear interpolation between
// frames takes the short way.
void push_quaternion(std::vector<float>& out, Eigen::Quaterniond q) {
  if (out.size() >= 4) {
    const size_t b = out.size() - 4;
    const double dot = out[b] * q.x() + out[b + 1] * q.y() + out[b + 2] * q.z() + out[b + 3] * q.w();
    if (dot < 0) q.coeffs() = -q.coeffs();
  }
  for (double c : {q.x(), q.y(), q.z(), q.w()}) out.push_back(static_cast<float>(c));
}

Eigen::Quaterniond quaternion_of(const double* axis_angle) {
  const Eigen::Vector3d aa(axis_angle[0], axis_angle[1], axis_angle[2]);
  const double angle = aa.norm();
  if (angle < 1e-12) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, aa / angle));
}

tinygltf::Value extras_of(const Sequence& s) {
  tinygltf::Value::Object o;
  o["generator"] = tinygltf::Value(std::string("bimart"));
  o["name"] = tinygltf::Value(s.name);
  o["fps"] = tinygltf::Value(s.fps);
  o["frames"] = tinygltf::Value(static_cast<int>(s.num_frames()));
  if (!s.category.empty()) o["category"] = tinygltf::Value(s.category);
  if (!s.kind.empty()) o["kind"] = tinygltf::Value(s.kind);
  return tinygltf::Value(o);
}

struct Animation {
  tinygltf::Animation anim;
  int times = -1;
  void channel(Builder& b, int node, const std::string& path, const std::vector<float>& values, int type) {
    tinygltf::AnimationSampler s;
    s.input = times;
    s.output = b.floats(values, type, 0, false);
    s.interpolation = "LINEAR";
    anim.samplers.push_back(s);
    tinygltf::AnimationChannel c;
    c.sampler = static_cast<int>(anim.samplers.size()) - 1;
    c.target_node = node;
    c.target_path = path;
    anim.channels.push_back(c);
  }
};

void add_object(Builder& b, Animation& anim, const ArticulatedObject& object, const at::Tensor& states,
                std::vector<int>& roots) {
  const std::int64_t n = states.size(0);
  const int bottom_mat = b.material("object_bottom", {0.30, 0.50, 0.85}, 0.6);
  const int top_mat = b.material("object_top", {0.95, 0.55, 0.20}, 0.6);
  auto part_mesh = [&](const TriangleMesh& mesh, const std::string& name, int material) {
    tinygltf::Primitive p;
    p.attributes["POSITION"] = b.floats(flat(mesh.vertices), TINYGLTF_TYPE_VEC3, kArrayBuffer, true);
    p.attributes["NORMAL"] = b.floats(normals(mesh), TINYGLTF_TYPE_VEC3, kArrayBuffer, false);
    p.indices = b.integers(indices(mesh), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, kElementBuffer);
    p.material = material;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh m;
    m.name = name + "_mesh";
    m.primitives.push_back(p);
    b.model.meshes.push_back(m);
    return static_cast<int>(b.model.meshes.size()) - 1;
  };
  tinygltf::Node bottom, top, root;
  bottom.name = "object_bottom";
  bottom.mesh = part_mesh(object.bottom, "object_bottom", bottom_mat);
  top.name = "object_top";
  top.mesh = part_mesh(object.top, "object_top", top_mat);
  const int bottom_id = b.node(bottom), top_id = b.node(top);
  root.name = "object";
  root.children = {bottom_id, top_id};
  const int root_id = b.node(root);
  roots.push_back(root_id);

  std::vector<float> hinge, rotation, translation;
  for (std::int64_t t = 0; t < n; ++t) {
    const ObjectState s = ObjectState::from_row(states[t].data_ptr<double>());
    push_quaternion(hinge, Eigen::Quaterniond(Eigen::AngleAxisd(s.angle, -Eigen::Vector3d::UnitZ())));
    push_quaternion(rotation, quaternion_of(s.root_rotation.data()));
    for (int k = 0; k < 3; ++k) translation.push_back(static_cast<float>(s.root_translation[k]));
  }
  anim.channel(b, top_id, "rotation", hinge, TINYGLTF_TYPE_VEC4);
  anim.channel(b, root_id, "rotation", rotation, TINYGLTF_TYPE_VEC4);
  anim.channel(b, root_id, "translation", translation, TINYGLTF_TYPE_VEC3);
}

constexpr auto& kJointNames = HandModel::kJointNames;

int add_hand(Builder& b, Animation& anim, const HandModel& m, const HandParams& params, int h,
             const GltfOptions& options, GltfSummary& summary, std::vector<int>& roots) {
  const std::string side = h == 0 ? "left" : "right";
  const int V = m.num_vertices();
  constexpr int kJ = HandModel::kNumJoints;
  const at::Tensor rot = params.rot.to(at::kDouble).contiguous(), pose = params.pose.to(at::kDouble).contiguous(),
                   trans = params.trans.to(at::kDouble).contiguous(), beta = params.shape.to(at::kDouble).contiguous();
  const std::int64_t n = rot.size(0);

  // Bind pose: the flat hand at the sequence's β (shape blend shapes applied), rest joints.
  Eigen::VectorXd b_vec = Eigen::Map<const Eigen::VectorXd>(beta.data_ptr<double>(), HandModel::kNumBetas);
  TriangleMesh shaped;
  shaped.faces = m.faces;
  shaped.vertices = m.v_template;
  {
    const Eigen::VectorXd d = m.shapedirs * b_vec;
    for (int v = 0; v < V; ++v)
      for (int k = 0; k < 3; ++k) shaped.vertices(v, k) += d[3 * v + k];
  }
  const Eigen::Matrix<double, kJ, 3> J = m.j_regressor * shaped.vertices;

  // Skinning weights: the largest first, 4 per JOINTS_n/WEIGHTS_n set.
  int influences = 1;
  for (int v = 0; v < V; ++v) influences = std::max(influences, int((m.weights.row(v).array() > 0).count()));
  const int sets = (influences + 3) / 4;
  summary.influences[h] = influences;
  std::vector<std::vector<std::uint8_t>> joints(sets, std::vector<std::uint8_t>(4 * V, 0));
  std::vector<std::vector<float>> weights(sets, std::vector<float>(4 * V, 0.f));
  for (int v = 0; v < V; ++v) {
    std::array<int, kJ> order;
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int c) { return m.weights(v, a) > m.weights(v, c); });
    for (int i = 0; i < influences; ++i) {
      const double w = m.weights(v, order[i]);
      if (w <= 0) break;
      joints[i / 4][4 * v + i % 4] = static_cast<std::uint8_t>(order[i]);
      weights[i / 4][4 * v + i % 4] = static_cast<float>(w);
    }
  }

  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = b.floats(flat(shaped.vertices), TINYGLTF_TYPE_VEC3, kArrayBuffer, true);
  prim.attributes["NORMAL"] = b.floats(normals(shaped), TINYGLTF_TYPE_VEC3, kArrayBuffer, false);
  for (int s = 0; s < sets; ++s) {
    prim.attributes["JOINTS_" + std::to_string(s)] =
        b.integers(joints[s], TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, kArrayBuffer);
    prim.attributes["WEIGHTS_" + std::to_string(s)] = b.floats(weights[s], TINYGLTF_TYPE_VEC4, kArrayBuffer, false);
  }
  prim.indices = b.integers(indices(shaped), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, kElementBuffer);
  prim.material = h == 0 ? b.material("left_hand", {0.93, 0.74, 0.62}, 0.5) : b.material("right_hand", {0.72, 0.50, 0.40}, 0.5);
  prim.mode = TINYGLTF_MODE_TRIANGLES;

  // Pose correctives. Feature c per frame is the entry (R_j - I)_e the corrective column c of
  // posedirs is weighted by. One morph target per column that is non-zero and used by the
  // motion, scaled so that its weight stays in [0, 1]: target = hi * D_c with weight f / hi
  // for f >= 0, and a second target lo * D_c with weight f / lo for a column whose feature
  // also goes negative. Exact at every frame; and Blender 3.4's importer, which clamps
  // shape-key values to [min(0, first keyframe), 1], then reproduces it too.
  std::vector<std::vector<double>> features(HandModel::kNumPoseFeatures, std::vector<double>(n));
  for (std::int64_t t = 0; t < n; ++t) {
    const double* th = pose[t].data_ptr<double>();
    for (int j = 1; j < kJ; ++j) {
      double R[9];
      axis_angle_to_matrix(th + 3 * (j - 1), R);
      for (int e = 0; e < 9; ++e) features[9 * (j - 1) + e][t] = R[e] - (e % 4 == 0 ? 1.0 : 0.0);
    }
  }
  struct Target {
    int column;
    double scale;  // the target is scale * D_c; its weight max(0, f / scale)
  };
  std::vector<Target> targets;
  if (options.correctives)
    for (int c = 0; c < HandModel::kNumPoseFeatures; ++c) {
      if (!(m.posedirs.col(c).cwiseAbs().maxCoeff() > 0)) continue;
      const auto [lo, hi] = std::minmax_element(features[c].begin(), features[c].end());
      if (*hi > 0) targets.push_back({c, *hi});
      if (*lo < 0) targets.push_back({c, *lo});
    }
  std::vector<std::string> target_names;
  for (const Target& tg : targets) {
    std::vector<float> d(3 * V);
    for (int i = 0; i < 3 * V; ++i) d[i] = static_cast<float>(tg.scale * m.posedirs(i, tg.column));
    prim.targets.push_back({{"POSITION", b.floats(d, TINYGLTF_TYPE_VEC3, kArrayBuffer, true)}});
    const int joint = 1 + tg.column / 9, e = tg.column % 9;
    target_names.push_back(fmt::format("{}_R{}{}{}", kJointNames[joint], e / 3, e % 3, tg.scale > 0 ? '+' : '-'));
  }
  summary.morph_targets[h] = static_cast<int>(targets.size());

  tinygltf::Mesh mesh;
  mesh.name = side + "_hand_mesh";
  mesh.primitives.push_back(prim);
  if (!targets.empty()) {
    mesh.weights.assign(targets.size(), 0.0);
    tinygltf::Value::Array names;
    for (const auto& t : target_names) names.emplace_back(t);
    tinygltf::Value::Object extras;
    extras["targetNames"] = tinygltf::Value(names);  // read by Blender and three.js
    mesh.extras = tinygltf::Value(extras);
  }
  b.model.meshes.push_back(mesh);
  const int mesh_id = static_cast<int>(b.model.meshes.size()) - 1;

  // Skeleton: joint 0 at the scene root (translation J_0 + trans, rotation = global rot),
  // joint j under its parent at J_j - J_parent; inverse bind matrices translate by -J_j.
  std::array<int, kJ> node_ids{};
  for (int j = 0; j < kJ; ++j) {
    tinygltf::Node nd;
    nd.name = side + "_" + kJointNames[j];
    const int p = m.parents[j];
    const Eigen::Vector3d offset = p < 0 ? Eigen::Vector3d(J.row(j).transpose()) : Eigen::Vector3d((J.row(j) - J.row(p)).transpose());
    nd.translation = {offset[0], offset[1], offset[2]};
    node_ids[j] = b.node(nd);
  }
  for (int j = 1; j < kJ; ++j) b.model.nodes[node_ids[m.parents[j]]].children.push_back(node_ids[j]);
  std::vector<float> ibm;
  for (int j = 0; j < kJ; ++j) {
    const float cols[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,
                            float(-J(j, 0)), float(-J(j, 1)), float(-J(j, 2)), 1};  // column-major
    ibm.insert(ibm.end(), cols, cols + 16);
  }
  tinygltf::Skin skin;
  skin.name = side + "_hand_skin";
  skin.inverseBindMatrices = b.floats(ibm, TINYGLTF_TYPE_MAT4, 0, false);
  skin.skeleton = node_ids[0];
  skin.joints.assign(node_ids.begin(), node_ids.end());
  b.model.skins.push_back(skin);

  // The skeleton under its own group node, so that importers (Blender) make one armature per
  // hand; the skinned mesh node at the scene root (its own transform would be ignored).
  tinygltf::Node rig;
  rig.name = side + "_hand_rig";
  rig.children = {node_ids[0]};
  roots.push_back(b.node(rig));
  tinygltf::Node mesh_node;
  mesh_node.name = side + "_hand";
  mesh_node.mesh = mesh_id;
  mesh_node.skin = static_cast<int>(b.model.skins.size()) - 1;
  roots.push_back(b.node(mesh_node));

  // Animation: per frame the 16 rotations, the root translation and the corrective weights.
  std::array<std::vector<float>, kJ> rotations;
  std::vector<float> root_translation, morph;
  for (std::int64_t t = 0; t < n; ++t) {
    push_quaternion(rotations[0], quaternion_of(rot[t].data_ptr<double>()));
    const double* th = pose[t].data_ptr<double>();
    for (int j = 1; j < kJ; ++j) push_quaternion(rotations[j], quaternion_of(th + 3 * (j - 1)));
    const double* tr = trans[t].data_ptr<double>();
    for (int k = 0; k < 3; ++k) root_translation.push_back(static_cast<float>(J(0, k) + tr[k]));
    for (const Target& tg : targets) morph.push_back(static_cast<float>(std::max(0.0, features[tg.column][t] / tg.scale)));
  }
  anim.channel(b, node_ids[0], "translation", root_translation, TINYGLTF_TYPE_VEC3);
  for (int j = 0; j < kJ; ++j) anim.channel(b, node_ids[j], "rotation", rotations[j], TINYGLTF_TYPE_VEC4);
  if (!targets.empty()) anim.channel(b, roots.back(), "weights", morph, TINYGLTF_TYPE_SCALAR);
  return mesh_id;
}

}  // namespace

std::array<std::string, HandModel::kNumJoints> gltf_joint_names(HandSide side) {
  std::array<std::string, HandModel::kNumJoints> out;
  for (int j = 0; j < HandModel::kNumJoints; ++j)
    out[j] = std::string(side == HandSide::Left ? "left_" : "right_") + kJointNames[j];
  return out;
}

std::string build_glb(const Sequence& sequence, const ArticulatedObject& object,
                      const std::array<const HandModel*, 2>& models, const GltfOptions& options,
                      GltfSummary* summary) {
  sequence.validate();
  const std::int64_t n = sequence.num_frames();
  if (n < 1) throw Error("glTF export: the sequence has no frames");
  for (int h = 0; h < 2; ++h)
    if (models[h]->side != (h == 0 ? HandSide::Left : HandSide::Right))
      throw Error(std::string("glTF export: the ") + (h == 0 ? "left" : "right") + " hand model is of the other side");
  GltfSummary sum;
  sum.frames = n;
  Builder b;
  b.model.asset.version = "2.0";
  b.model.asset.generator = std::string("bimart ") + BIMART_VERSION_STRING;

  Animation anim;
  anim.anim.name = sequence.name.empty() ? "motion" : sequence.name;
  std::vector<float> times(n);
  for (std::int64_t t = 0; t < n; ++t) times[t] = static_cast<float>(double(t) / sequence.fps);
  anim.times = b.floats(times, TINYGLTF_TYPE_SCALAR, 0, true);

  std::vector<int> roots;
  add_object(b, anim, object, sequence.object_states.to(at::kDouble).contiguous(), roots);
  for (int h = 0; h < 2; ++h) add_hand(b, anim, *models[h], sequence.hands.hands[h], h, options, sum, roots);
  b.model.animations.push_back(anim.anim);

  tinygltf::Scene scene;
  scene.name = sequence.name;
  scene.nodes = roots;
  scene.extras = extras_of(sequence);
  b.model.scenes.push_back(scene);
  b.model.defaultScene = 0;

  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&b.model, out, false, true)) throw Error("glTF export: tinygltf could not write the scene");
  if (summary) *summary = sum;
  return out.str();
}

GltfSummary write_glb(const Sequence& sequence, const ArticulatedObject& object,
                      const std::array<const HandModel*, 2>& models, const std::string& path,
                      const GltfOptions& options) {
  GltfSummary sum;
  const std::string bytes = build_glb(sequence, object, models, options, &sum);
  write_file_atomically(path, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
  return sum;
}

}  // namespace bimart
