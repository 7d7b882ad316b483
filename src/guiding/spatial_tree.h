// The spatial half of the SD-tree (Müller et al. 2017, §3): a binary tree over a cube around
// the scene, each node halving its cell along x, y, z in turn, each leaf pointing at a payload
// (its directional distribution). Leaves split where records or photons crowd them, so the
// spatial resolution follows where light transport happens.
#pragma once
#include <cstdint>
#include <vector>

#include "core/common.h"

namespace pl {

class SpatialBinaryTree {
 public:
  SpatialBinaryTree() = default;
  // A cube centred on the bounds' centre, its side the bounds' longest extent (plus a margin,
  // so that points on the bounds fall inside); one leaf holding payload 0.
  SpatialBinaryTree(const Vec3& lo, const Vec3& hi);

  // The payload of the leaf holding p (points outside the cube are clamped into it).
  uint32_t leafAt(const Vec3& p) const { return nodes_[nodeAt(p)].payload; }
  uint32_t nodeAt(const Vec3& p) const;

  // Splits leaf node `node` in two; both halves keep its payload index for the caller to
  // replace (setPayload). Returns the two new nodes.
  std::pair<uint32_t, uint32_t> split(uint32_t node);
  void setPayload(uint32_t node, uint32_t payload) { nodes_[node].payload = payload; }

  struct Node {
    uint32_t child[2] = {0, 0};  // 0: a leaf (node 0 is the root, never a child)
    uint8_t axis = 0;            // the axis this node halves, when it is not a leaf
    uint32_t payload = 0;        // leaves only
    int depth = 0;
    bool isLeaf() const { return child[0] == 0; }
  };
  const std::vector<Node>& nodes() const { return nodes_; }
  size_t leaves() const;
  // A node's cell (for tests and the photon guide's queries).
  void cell(uint32_t node, Vec3* lo, Vec3* hi) const;

 private:
  std::vector<Node> nodes_{Node()};
  Vec3 origin_{0.0f};
  float size_ = 1.0f;
};

}  // namespace pl
