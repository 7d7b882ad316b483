#include "guiding/spatial_tree.h"

namespace pl {

SpatialBinaryTree::SpatialBinaryTree(const Vec3& lo, const Vec3& hi) {
  Vec3 extent = hi - lo;
  size_ = std::max(std::max(extent.x, extent.y), std::max(extent.z, 1e-6f)) * 1.002f;
  origin_ = 0.5f * (lo + hi) - Vec3(0.5f * size_);
}

uint32_t SpatialBinaryTree::nodeAt(const Vec3& p) const {
  // p in the cube's unit coordinates; each level maps the chosen half back onto [0, 1).
  Vec3 x = glm::clamp((p - origin_) / size_, Vec3(0.0f), Vec3(0x1.fffffep-1f));
  uint32_t n = 0;
  while (!nodes_[n].isLeaf()) {
    const Node& node = nodes_[n];
    float& c = x[node.axis];
    int side = c >= 0.5f;
    c = std::min(2 * c - float(side), 0x1.fffffep-1f);
    n = node.child[side];
  }
  return n;
}

std::pair<uint32_t, uint32_t> SpatialBinaryTree::split(uint32_t node) {
  uint32_t a = uint32_t(nodes_.size());
  Node child;
  child.payload = nodes_[node].payload;
  child.depth = nodes_[node].depth + 1;
  child.axis = uint8_t((nodes_[node].axis + 1) % 3);  // the axis the children will halve
  nodes_.push_back(child);
  nodes_.push_back(child);
  nodes_[node].child[0] = a;
  nodes_[node].child[1] = a + 1;
  return {a, a + 1};
}

size_t SpatialBinaryTree::leaves() const {
  size_t n = 0;
  for (const Node& node : nodes_) n += node.isLeaf();
  return n;
}

void SpatialBinaryTree::cell(uint32_t target, Vec3* lo, Vec3* hi) const {
  // Walk down from the root to `target`, halving the cell on the way (parents precede children).
  std::vector<uint32_t> parent(nodes_.size(), 0);
  for (uint32_t n = 0; n < nodes_.size(); ++n)
    if (!nodes_[n].isLeaf()) parent[nodes_[n].child[0]] = parent[nodes_[n].child[1]] = n;
  std::vector<uint32_t> path{target};
  while (path.back() != 0) path.push_back(parent[path.back()]);
  Vec3 l = origin_, h = origin_ + Vec3(size_);
  for (size_t i = path.size(); i-- > 1;) {
    const Node& node = nodes_[path[i]];
    float mid = 0.5f * (l[node.axis] + h[node.axis]);
    if (node.child[0] == path[i - 1]) h[node.axis] = mid;
    else l[node.axis] = mid;
  }
  *lo = l, *hi = h;
}

}  // namespace pl
