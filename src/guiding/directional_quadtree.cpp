#include "guiding/directional_quadtree.h"

#include <algorithm>
#include <functional>

namespace pl {

namespace {

inline int quadrant(Vec2 p) { return int(p.x >= 0.5f) + 2 * int(p.y >= 0.5f); }
// p in the quadrant's own unit square.
inline Vec2 intoQuadrant(Vec2 p, int q) {
  return Vec2(2 * p.x - float(q & 1), 2 * p.y - float(q >> 1));
}

}  // namespace

DirectionalQuadtree::DirectionalQuadtree(std::vector<Node> shape, std::vector<float> energy)
    : nodes_(std::move(shape)), energy_(std::move(energy)) {
  total_ = energy_[0] + energy_[1] + energy_[2] + energy_[3];
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const float* e = &energy_[4 * n];
    float sum = e[0] + e[1] + e[2] + e[3];
    for (int q = 0; q < 4; ++q) nodes_[n].probability[q] = sum > 0 ? e[q] / sum : 0.0f;
  }
}

float DirectionalQuadtree::pdfSquare(Vec2 p) const {
  if (empty()) return 0.0f;
  // Each level multiplies by the quadrant's probability over its share of the area (¼).
  float density = 1.0f;
  uint32_t n = 0;
  for (;;) {
    const Node& node = nodes_[n];
    int q = quadrant(p);
    density *= 4 * node.probability[q];
    if (node.child[q] == 0 || density == 0) return density;
    p = intoQuadrant(p, q);
    n = node.child[q];
  }
}

Vec2 DirectionalQuadtree::sampleSquare(Vec2 u, float* pdfSquare) const {
  // Descend: choose the column (u ≥ ½ or not) by its probability, then the row within it,
  // reusing each coordinate of u rescaled to [0, 1) for the next level. At a leaf cell the rest
  // of u places the point uniformly.
  Vec2 origin(0.0f), size(1.0f);
  float density = 1.0f;
  uint32_t n = 0;
  for (;;) {
    const Node& node = nodes_[n];
    const float* P = node.probability;
    float left = P[0] + P[2], right = P[1] + P[3];
    int column;
    if (u.x * (left + right) < left) column = 0, u.x = u.x * (left + right) / left;
    else column = 1, u.x = (u.x * (left + right) - left) / right;
    float bottom = P[column], top = P[column + 2];
    int row;
    if (u.y * (bottom + top) < bottom) row = 0, u.y = u.y * (bottom + top) / bottom;
    else row = 1, u.y = (u.y * (bottom + top) - bottom) / top;
    u = glm::clamp(u, Vec2(0.0f), Vec2(0x1.fffffep-1f));
    int q = column + 2 * row;
    density *= 4 * P[q];
    size *= 0.5f;
    origin += Vec2(float(column), float(row)) * size;
    if (node.child[q] == 0) {
      *pdfSquare = density;
      return glm::clamp(origin + u * size, Vec2(0.0f), Vec2(0x1.fffffep-1f));
    }
    n = node.child[q];
  }
}

int DirectionalQuadtree::depth() const {
  std::function<int(uint32_t)> d = [&](uint32_t n) {
    int deepest = 0;
    for (uint32_t c : nodes_[n].child)
      if (c) deepest = std::max(deepest, d(c));
    return 1 + deepest;
  };
  return d(0);
}

size_t DirectionalQuadtree::leafCells() const {
  size_t cells = 0;
  for (const Node& node : nodes_)
    for (uint32_t c : node.child) cells += c == 0;
  return cells;
}

DirectionalQuadtree DirectionalQuadtree::fromDirections(std::vector<WeightedDirection> directions, float threshold,
                                                        int minCount, int maxDepth) {
  double total = 0;
  for (auto& d : directions) total += d.weight;
  std::vector<Node> nodes(1);
  std::vector<float> energy(4, 0.0f);
  if (!(total > 0)) return DirectionalQuadtree(std::move(nodes), std::move(energy));
  // Partition the directions into the node's quadrants (in their coordinates within it), then
  // split the quadrants that hold enough weight and enough directions.
  std::function<void(uint32_t, std::vector<WeightedDirection>&, int)> build =
      [&](uint32_t n, std::vector<WeightedDirection>& items, int depth) {
        std::vector<WeightedDirection> part[4];
        double weight[4] = {0, 0, 0, 0};
        for (auto& d : items) {
          int q = quadrant(d.square);
          weight[q] += d.weight;
          part[q].push_back({glm::clamp(intoQuadrant(d.square, q), Vec2(0.0f), Vec2(0x1.fffffep-1f)), d.weight});
        }
        items.clear();
        items.shrink_to_fit();
        for (int q = 0; q < 4; ++q) energy[4 * n + q] = float(weight[q] / total);
        for (int q = 0; q < 4; ++q) {
          if (depth >= maxDepth || weight[q] <= threshold * total || int(part[q].size()) <= minCount) continue;
          uint32_t c = uint32_t(nodes.size());
          nodes.emplace_back();
          energy.resize(energy.size() + 4, 0.0f);
          nodes[n].child[q] = c;
          build(c, part[q], depth + 1);
        }
      };
  build(0, directions, 1);
  return DirectionalQuadtree(std::move(nodes), std::move(energy));
}

// --- the training form ---

QuadtreeRecorder::QuadtreeRecorder(int threads)
    : shape_(1), threads_(std::max(1, threads)), units_(4 * size_t(threads_), 0), records_(8 * size_t(threads_), 0) {}

QuadtreeRecorder::QuadtreeRecorder(const DirectionalQuadtree& from, float threshold, int maxDepth, int threads)
    : threads_(std::max(1, threads)) {
  using Node = DirectionalQuadtree::Node;
  const auto& old = from.nodes();
  const float total = from.total();
  shape_.assign(1, Node());
  // (new node, old node or -1 where the old tree had a leaf cell, the energies to decide with,
  // depth). Where the old tree ends, a split cell's energy is shared equally among its quadrants.
  struct Item {
    uint32_t node;
    int64_t oldNode;
    float energy[4];
    int depth;
  };
  std::vector<Item> stack;
  Item root{0, 0, {0, 0, 0, 0}, 1};
  for (int q = 0; q < 4; ++q) root.energy[q] = total > 0 ? from.energy(0, q) : 0.0f;
  stack.push_back(root);
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    for (int q = 0; q < 4; ++q) {
      // Without energy (the first iteration, or a leaf nothing reached) the tree stays coarse.
      float fraction = total > 0 ? it.energy[q] / total : 0.0f;
      if (it.depth >= maxDepth || !(fraction > threshold)) continue;
      uint32_t c = uint32_t(shape_.size());
      shape_.emplace_back();
      shape_[it.node].child[q] = c;
      Item child{c, -1, {0, 0, 0, 0}, it.depth + 1};
      if (it.oldNode >= 0 && old[size_t(it.oldNode)].child[q] != 0) {
        child.oldNode = old[size_t(it.oldNode)].child[q];
        for (int k = 0; k < 4; ++k) child.energy[k] = from.energy(size_t(child.oldNode), k);
      } else {
        for (int k = 0; k < 4; ++k) child.energy[k] = it.energy[q] / 4;
      }
      stack.push_back(child);
    }
  }
  units_.assign(size_t(threads_) * 4 * shape_.size(), 0);
  records_.assign(8 * size_t(threads_), 0);
}

void QuadtreeRecorder::record(Vec2 p, uint64_t units, int thread) {
  ++records_[8 * size_t(thread)];
  if (units == 0) return;
  uint32_t n = 0;
  for (;;) {
    int q = quadrant(p);
    uint32_t c = shape_[n].child[q];
    if (c == 0) {
      units_[(size_t(thread) * shape_.size() + n) * 4 + size_t(q)] += units;
      return;
    }
    p = intoQuadrant(p, q);
    n = c;
  }
}

uint64_t QuadtreeRecorder::records() const {
  uint64_t n = 0;
  for (int t = 0; t < threads_; ++t) n += records_[8 * size_t(t)];
  return n;
}

void QuadtreeRecorder::setRecords(uint64_t n) {
  std::fill(records_.begin(), records_.end(), 0);
  records_[0] = n;
}

DirectionalQuadtree QuadtreeRecorder::finish(double unitValue) const {
  const size_t nodes = shape_.size();
  // Children come after their parents (built depth-first from the root), so one backward sweep
  // sums every subtree before its parent reads it.
  std::vector<float> energy(4 * nodes, 0.0f);
  std::vector<double> sums(nodes, 0.0);
  for (size_t n = nodes; n-- > 0;) {
    double s = 0;
    for (int q = 0; q < 4; ++q) {
      uint32_t c = shape_[n].child[q];
      double e;
      if (c) {
        e = sums[c];
      } else {
        uint64_t units = 0;
        for (int t = 0; t < threads_; ++t) units += units_[(size_t(t) * nodes + n) * 4 + size_t(q)];
        e = double(units) * unitValue;
      }
      energy[4 * n + size_t(q)] = float(e);
      s += e;
    }
    sums[n] = s;
  }
  DirectionalQuadtree tree(shape_, std::move(energy));
  const uint64_t n = records();
  if (n > 0) tree.setRadianceScale(float(sums[0] / double(n)), false);
  return tree;
}

}  // namespace pl
