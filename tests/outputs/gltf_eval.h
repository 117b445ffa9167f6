// A small glTF evaluator for tests: node transforms at a keyframe, skinning with morph
// targets, read back from the .glb bytes with tinygltf. Independent of the writer's code.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <tiny_gltf.h>

#include "core/util/error.h"

namespace bimart::test {

inline tinygltf::Model load_glb(const std::string& bytes) {
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  if (!loader.LoadBinaryFromMemory(&m, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                   static_cast<unsigned>(bytes.size())))
    throw Error("tinygltf: " + err);
  return m;
}

template <class T>
std::vector<T> read_accessor(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors.at(index);
  const tinygltf::BufferView& v = m.bufferViews.at(a.bufferView);
  const size_t n = a.count * tinygltf::GetNumComponentsInType(a.type);
  if (tinygltf::GetComponentSizeInBytes(a.componentType) != sizeof(T)) throw Error("accessor component size");
  std::vector<T> out(n);
  std::memcpy(out.data(), m.buffers[v.buffer].data.data() + v.byteOffset + a.byteOffset, n * sizeof(T));
  return out;
}

inline int node_named(const tinygltf::Model& m, const std::string& name) {
  for (size_t i = 0; i < m.nodes.size(); ++i)
    if (m.nodes[i].name == name) return static_cast<int>(i);
  throw Error("no node " + name);
}

// World matrices of every node at keyframe k of animation 0; morph weights per node.
struct Evaluated {
  std::vector<Eigen::Matrix4d> world;
  std::map<int, std::vector<double>> weights;
};

inline Evaluated evaluate(const tinygltf::Model& m, int k) {
  const size_t N = m.nodes.size();
  std::vector<Eigen::Vector3d> T(N, Eigen::Vector3d::Zero());
  std::vector<Eigen::Quaterniond> R(N, Eigen::Quaterniond::Identity());
  Evaluated e;
  for (size_t i = 0; i < N; ++i) {
    const auto& n = m.nodes[i];
    if (n.translation.size() == 3) T[i] = Eigen::Vector3d(n.translation[0], n.translation[1], n.translation[2]);
    if (n.rotation.size() == 4) R[i] = Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
  }
  for (const auto& ch : m.animations.at(0).channels) {
    const auto& s = m.animations[0].samplers[ch.sampler];
    const std::vector<float> out = read_accessor<float>(m, s.output);
    const size_t keys = m.accessors[s.input].count;
    const size_t width = out.size() / keys;
    const float* v = out.data() + width * k;
    if (ch.target_path == "translation") T[ch.target_node] = Eigen::Vector3d(v[0], v[1], v[2]);
    if (ch.target_path == "rotation") R[ch.target_node] = Eigen::Quaterniond(v[3], v[0], v[1], v[2]).normalized();
    if (ch.target_path == "weights") e.weights[ch.target_node] = std::vector<double>(v, v + width);
  }
  e.world.assign(N, Eigen::Matrix4d::Identity());
  std::function<void(int, const Eigen::Matrix4d&)> walk = [&](int i, const Eigen::Matrix4d& parent) {
    Eigen::Matrix4d local = Eigen::Matrix4d::Identity();
    local.topLeftCorner<3, 3>() = R[i].toRotationMatrix();
    local.topRightCorner<3, 1>() = T[i];
    e.world[i] = parent * local;
    for (int c : m.nodes[i].children) walk(c, e.world[i]);
  };
  for (int r : m.scenes.at(0).nodes) walk(r, Eigen::Matrix4d::Identity());
  return e;
}

// Vertices [V, 3] of the mesh on `node` at keyframe k: skinned when the node has a skin,
// else moved by the node's world matrix; morph targets applied with the node's weights.
// `max_sets` > 0: only the first sets of joints, weights renormalised (as three.js does with
// its 4 influences).
inline Eigen::MatrixX3d node_vertices(const tinygltf::Model& m, int node, int k, bool morphs = true, int max_sets = 0) {
  const Evaluated e = evaluate(m, k);
  const auto& prim = m.meshes.at(m.nodes[node].mesh).primitives.at(0);
  const std::vector<float> pos = read_accessor<float>(m, prim.attributes.at("POSITION"));
  const size_t V = pos.size() / 3;
  Eigen::MatrixX3d p(V, 3);
  for (size_t v = 0; v < V; ++v) p.row(v) << pos[3 * v], pos[3 * v + 1], pos[3 * v + 2];
  if (morphs && e.weights.count(node))
    for (size_t t = 0; t < prim.targets.size(); ++t) {
      const std::vector<float> d = read_accessor<float>(m, prim.targets[t].at("POSITION"));
      const double w = e.weights.at(node)[t];
      for (size_t v = 0; v < V; ++v) p.row(v) += w * Eigen::RowVector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2]);
    }
  Eigen::MatrixX3d out(V, 3);
  const int skin = m.nodes[node].skin;
  if (skin < 0) {
    for (size_t v = 0; v < V; ++v) out.row(v) = (e.world[node] * p.row(v).transpose().homogeneous()).head<3>().transpose();
    return out;
  }
  const auto& sk = m.skins[skin];
  const std::vector<float> ibm = read_accessor<float>(m, sk.inverseBindMatrices);
  std::vector<Eigen::Matrix4d> J(sk.joints.size());
  for (size_t j = 0; j < sk.joints.size(); ++j)
    J[j] = e.world[sk.joints[j]] * Eigen::Map<const Eigen::Matrix4f>(ibm.data() + 16 * j).cast<double>();
  out.setZero();
  Eigen::VectorXd total = Eigen::VectorXd::Zero(V);
  for (int set = 0; prim.attributes.count("JOINTS_" + std::to_string(set)) && (max_sets <= 0 || set < max_sets); ++set) {
    const auto joints = read_accessor<std::uint8_t>(m, prim.attributes.at("JOINTS_" + std::to_string(set)));
    const auto weights = read_accessor<float>(m, prim.attributes.at("WEIGHTS_" + std::to_string(set)));
    for (size_t v = 0; v < V; ++v)
      for (int i = 0; i < 4; ++i) {
        total[v] += weights[4 * v + i];
        out.row(v) += weights[4 * v + i] *
                      (J[joints[4 * v + i]] * p.row(v).transpose().homogeneous()).head<3>().transpose();
      }
  }
  for (size_t v = 0; v < V; ++v) out.row(v) /= total[v];
  return out;
}

}  // namespace bimart::test
