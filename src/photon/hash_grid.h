// Fixed-radius range search over points, rebuilt every iteration: the light vertices that vertex
// merging gathers (Georgiev et al. 2012; Hachisuka et al. 2008 used the same grid for PPM).
//
// Cells are 2r wide, so the ball of radius r around x overlaps only the 2×2×2 cells nearest to x
// (per axis: x's own cell and the neighbour on the side x is closer to). Cells are hashed into as
// many buckets as there are points; a counting sort lays the points out bucket by bucket, keeping
// their input order within a bucket, so a query visits them in the same order whatever the
// thread count that traced them. Two of the eight cells may hash to one bucket: each bucket is
// visited once; a bit per bucket says whether it holds any point, so that the empty ones among
// the eight (about half, beside a surface) cost an L2 hit instead of two cache misses. The grid holds copies of the points (any type with a position `p`): what a
// query needs sits beside the position it tests, in the same cache line, and not behind an
// index into a larger array (the merges' cache misses halved).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/common.h"

namespace pl {

template <typename Point>
class HashGrid {
 public:
  void build(const std::vector<Point>& input, float radius) {
    const size_t count = input.size();
    auto positionOf = [&](size_t i) { return input[i].p; };
    radius_ = radius;
    radius2_ = radius * radius;
    cellSize_ = 2.0f * radius;
    points_.clear();
    buckets_ = std::max<size_t>(1, count);
    start_.assign(buckets_ + 1, 0);
    occupied_.assign((buckets_ + 63) / 64, 0);
    if (count == 0) return;
    lo_ = Vec3(INFINITY);
    for (size_t i = 0; i < count; ++i) lo_ = glm::min(lo_, positionOf(i));
    std::vector<uint32_t> bucketOf(count);
    for (size_t i = 0; i < count; ++i) {
      Vec3 c = glm::floor((positionOf(i) - lo_) / cellSize_);
      bucketOf[i] = bucket(int(c.x), int(c.y), int(c.z));
      ++start_[bucketOf[i] + 1];
      occupied_[bucketOf[i] >> 6] |= uint64_t(1) << (bucketOf[i] & 63);
    }
    for (size_t b = 0; b < buckets_; ++b) start_[b + 1] += start_[b];
    points_.resize(count);
    std::vector<uint32_t> next(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < count; ++i) points_[next[bucketOf[i]]++] = input[i];
  }

  // fn(point) for every point within the radius of x (|p − x|² ≤ r²), bucket by bucket.
  template <typename Fn>
  void query(const Vec3& x, Fn&& fn) const {
    if (points_.empty()) return;
    Vec3 cell = (x - lo_) / cellSize_;
    Vec3 base = glm::floor(cell), frac = cell - base;
    int c0[3], c1[3];
    for (int a = 0; a < 3; ++a) {
      c0[a] = frac[a] < 0.5f ? int(base[a]) - 1 : int(base[a]);
      c1[a] = c0[a] + 1;
    }
    uint32_t visit[8];
    int n = 0;
    for (int ix : {c0[0], c1[0]})
      for (int iy : {c0[1], c1[1]})
        for (int iz : {c0[2], c1[2]}) {
          const uint32_t b = bucket(ix, iy, iz);
          if (occupied_[b >> 6] & (uint64_t(1) << (b & 63))) visit[n++] = b;
        }
    std::sort(visit, visit + n);
    uint32_t* end = std::unique(visit, visit + n);
    for (uint32_t* b = visit; b != end; ++b)
      for (uint32_t k = start_[*b]; k < start_[*b + 1]; ++k) {
        Vec3 d = points_[k].p - x;
        if (glm::dot(d, d) <= radius2_) fn(points_[k]);
      }
  }

  float radius() const { return radius_; }

 private:
  uint32_t bucket(int x, int y, int z) const {
    // Teschner et al. 2003's spatial hash.
    uint64_t h = (uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ (uint32_t(z) * 83492791u);
    return uint32_t(h % buckets_);
  }
  std::vector<Point> points_;
  std::vector<uint32_t> start_;
  std::vector<uint64_t> occupied_;
  size_t buckets_ = 1;
  Vec3 lo_{0.0f};
  float radius_ = 0, radius2_ = 0, cellSize_ = 1;
};

}  // namespace pl
