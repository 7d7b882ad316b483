#include <catch2/catch.hpp>

#include <cmath>

#include "core/qmc.h"
#include "core/rng.h"
#include "core/sampler.h"
#include "core/sampling.h"
#include "stats.h"

using namespace pl;

TEST_CASE("chi-square machinery: p-values of known distributions") {
  // Q(k/2, x/2) is the chi-square survival function: for 1 dof, P(χ² > 3.841) = 0.05.
  CHECK(test::gammaQ(0.5, 3.841 / 2) == Approx(0.05).epsilon(1e-3));
  CHECK(test::gammaQ(5.0, 18.307 / 2) == Approx(0.05).epsilon(1e-3));  // 10 dof
  // A fair die passes, a loaded one fails.
  Rng rng(1, 2);
  std::vector<double> fair(6, 0), loaded(6, 0), expected(6, 60000.0 / 6);
  for (int i = 0; i < 60000; ++i) {
    fair[rng.nextU32() % 6] += 1;
    float u = rng.uniform();
    loaded[u < 0.2f ? 0 : 1 + rng.nextU32() % 5] += 1;
  }
  CHECK(test::chiSquarePValue(fair, expected) > 1e-3);
  CHECK(test::chiSquarePValue(loaded, expected) < 1e-6);
}

TEST_CASE("rng: uniform in (0 1) - keyed streams differ and repeat") {
  Rng a = Rng::keyed(1, 10, 3), b = Rng::keyed(1, 10, 3), c = Rng::keyed(1, 10, 4), d = Rng::keyed(1, 11, 3);
  float x = a.uniform();
  CHECK(x == b.uniform());
  CHECK(x != c.uniform());
  CHECK(x != d.uniform());
  double sum = 0;
  Rng r(5, 0);
  for (int i = 0; i < 100000; ++i) {
    float u = r.uniform();
    REQUIRE(u >= 0.0f);
    REQUIRE(u < 1.0f);
    sum += u;
  }
  CHECK(sum / 100000 == Approx(0.5).margin(0.005));
}

TEST_CASE("rng: hashed streams (one per photon) repeat, differ, and are uncorrelated across indices") {
  Rng a = Rng::hashed(7, 100), b = Rng::hashed(7, 100), c = Rng::hashed(7, 101), d = Rng::hashed(8, 100);
  float x = a.uniform();
  CHECK(x == b.uniform());
  CHECK(x != c.uniform());
  CHECK(x != d.uniform());
  // The first numbers of consecutive streams, as the tracer draws them: uniform in mean and
  // variance, and no correlation between photon i's and photon i + 1's (|ρ| ~ 1/√n).
  const int n = 100000;
  double sum = 0, sum2 = 0, cross = 0;
  float previous = Rng::hashed(3, 0).uniform();
  for (int i = 1; i <= n; ++i) {
    float u = Rng::hashed(3, uint64_t(i)).uniform();
    sum += u, sum2 += u * u, cross += (u - 0.5) * (previous - 0.5);
    previous = u;
  }
  CHECK(sum / n == Approx(0.5).margin(0.005));
  CHECK(sum2 / n == Approx(1.0 / 3.0).margin(0.005));
  CHECK(std::abs(cross / n / (1.0 / 12.0)) < 0.015);
}

TEST_CASE("qmc: the Sobol' second dimension matches its direction numbers v_k = v_{k-1} ^ (v_{k-1} >> 1)") {
  // The definition, bit by bit: point i is the XOR of v_k over the set bits k of i, v_0 = 2^31.
  auto byDefinition = [](uint32_t index) {
    uint32_t result = 0, v = 1u << 31;
    for (int k = 0; k < 32; ++k, v ^= v >> 1)
      if (index >> k & 1u) result ^= v;
    return result;
  };
  // Its first points as fractions (the Sobol' sequence's second coordinate): 0, 1/2, 3/4, 1/4.
  CHECK(qmc::sobolSecond(0) == 0u);
  CHECK(qmc::sobolSecond(1) == 0x80000000u);
  CHECK(qmc::sobolSecond(2) == 0xc0000000u);
  CHECK(qmc::sobolSecond(3) == 0x40000000u);
  Rng rng(5);
  for (uint32_t i = 0; i < 100000; ++i) {
    const uint32_t index = i < 50000 ? i : rng.nextU32();
    if (qmc::sobolSecond(index) != byDefinition(index)) FAIL("index " << index);
  }
  CHECK(qmc::reverseBits(1u) == 0x80000000u);
  CHECK(qmc::reverseBits(0x12345678u) == 0x1e6a2c48u);
}

TEST_CASE("qmc: every power-of-two prefix of a scrambled, shuffled sequence is a (0, k, 2)-net") {
  // The first 2^k points put exactly one point in each of the 2^k cells 2^-a × 2^-(k-a), for
  // every a: what stratifies a pixel's first 2^k samples in every aspect ratio at once. Owen
  // scrambling the points and shuffling the index by another Owen scramble keep that.
  int broken = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed)
    for (int k = 1; k <= 10; ++k) {
      const int n = 1 << k;
      for (int a = 0; a <= k; ++a) {
        std::vector<int> cells(size_t(n), 0);
        for (int i = 0; i < n; ++i) {
          const Vec2 p = qmc::sobol2D(uint32_t(i), seed);
          if (!(p.x >= 0 && p.x < 1 && p.y >= 0 && p.y < 1)) FAIL("point outside [0, 1)²");
          ++cells[size_t(int(p.x * float(1 << a)) << (k - a) | int(p.y * float(1 << (k - a))))];
        }
        for (int c : cells) broken += c != 1;
      }
    }
  CHECK(broken == 0);
}

TEST_CASE("qmc: one point over many scrambles is uniform - and two sequences' points at one index are independent") {
  // Uniform: point 5 of 20 000 sequences on a 10×10 grid, chi-square (expected 200 per cell).
  const int seeds = 20000, bins = 10;
  std::vector<double> observed(bins * bins, 0.0), expected(bins * bins, double(seeds) / (bins * bins));
  for (int s = 0; s < seeds; ++s) {
    const Vec2 p = qmc::sobol2D(5, mix64(uint64_t(s)));
    ++observed[size_t(std::min(bins - 1, int(p.x * bins)) * bins + std::min(bins - 1, int(p.y * bins)))];
  }
  CHECK(test::chiSquarePValue(observed, expected) > 1e-3);
  // Independent: two sequences (two draws of one path) over 16 indices. Each puts 8 points in
  // its left half. If the draws are independent, P(both left) = 1/4 at every index, so q, the
  // indices left in both, has mean 4 (checked within 4 standard errors). Unshuffled indices
  // would pair the halves exactly, q ∈ {0, 8}: the same mean, but |q − 4| = 4 always, where a
  // uniformly random pairing gives E|q − 4| = 0.76 (hypergeometric); the bound 2 tells them apart.
  const int trials = 4000;
  double sum = 0, sumSquares = 0, deviation = 0;
  for (int t = 0; t < trials; ++t) {
    int q = 0;
    for (uint32_t i = 0; i < 16; ++i)
      q += qmc::sobol2D(i, mix64(uint64_t(2 * t))).x < 0.5f && qmc::sobol2D(i, mix64(uint64_t(2 * t + 1))).x < 0.5f;
    sum += q, sumSquares += double(q) * q, deviation += std::abs(q - 4);
  }
  const double mean = sum / trials, se = std::sqrt((sumSquares / trials - mean * mean) / trials);
  INFO("q " << mean << " ± " << se << ", mean |q - 4| " << deviation / trials);
  CHECK(std::abs(mean - 4.0) < 4 * se);
  CHECK(deviation / trials < 2.0);
}

TEST_CASE("qmc: a Sampler's Sobol' slots, made at once, are the points made one by one") {
  // sobol2DSlots hashes all of a path's slots in one vectorised loop; each must be sobol2D's
  // point for that slot's seed, bit for bit, and the Sampler must hand them out in slot order
  // (get1D takes a point's x), then continue with its own stream.
  int differ = 0;
  for (uint64_t key = 0; key < 200; ++key)
    for (uint32_t index : {0u, 1u, 5u, 255u, 1000003u}) {
      const uint64_t k = mix64(key);
      for (int count = 1; count <= qmc::kMaxSlots; ++count) {
        Vec2 points[qmc::kMaxSlots];
        qmc::sobol2DSlots(index, k, count, points);
        for (int slot = 0; slot < count; ++slot) {
          const Vec2 one = qmc::sobol2D(index, qmc::slotSeed(k, slot));
          differ += points[slot].x != one.x || points[slot].y != one.y;
        }
      }
      Rng a(key), b(key);
      Sampler sampler(a, true, k, index, 3);
      CHECK(sampler.get1D() == qmc::sobol2D(index, qmc::slotSeed(k, 0)).x);
      const Vec2 second = sampler.get2D(), expected = qmc::sobol2D(index, qmc::slotSeed(k, 1));
      CHECK((second.x == expected.x && second.y == expected.y));
      CHECK(sampler.get1D() == qmc::sobol2D(index, qmc::slotSeed(k, 2)).x);
      CHECK(sampler.get1D() == b.uniform());  // past the slots: the stream's first draw
    }
  CHECK(differ == 0);
}

TEST_CASE("AliasTable picks items in proportion to their weights") {
  AliasTable d({1.0f, 0.0f, 3.0f});
  CHECK(d.total() == Approx(4.0));
  CHECK(d.pmf(0) == Approx(0.25));
  CHECK(d.pmf(1) == 0.0f);
  std::vector<double> counts(3, 0);
  Rng rng(3, 3);
  for (int i = 0; i < 40000; ++i) {
    float pmf;
    size_t k = d.sample(rng.uniform(), &pmf);
    counts[k] += 1;
    REQUIRE(pmf == d.pmf(k));
  }
  CHECK(counts[1] == 0);
  CHECK(counts[0] / 40000 == Approx(0.25).margin(0.01));
}

TEST_CASE("AliasTable: the share of the unit interval mapped to each item is exactly its pmf") {
  // Not a statistical test: u runs over a grid of 2²⁰ points, so each item's count divided by
  // 2²⁰ is the measure of u that selects it, which must equal weight/total (to the grid's
  // resolution) for any weights, zeros included, and a zero weight must never be selected.
  Rng rng(5, 5);
  for (int trial = 0; trial < 20; ++trial) {
    size_t n = 1 + rng.nextU32() % 40;
    std::vector<float> w(n);
    for (float& x : w) x = rng.uniform() < 0.25f ? 0.0f : std::pow(10.0f, 4.0f * rng.uniform() - 2.0f);
    w[rng.nextU32() % n] = 1.0f;  // at least one positive weight
    AliasTable d(w);
    double total = 0;
    for (float x : w) total += x;
    const int grid = 1 << 20;
    std::vector<double> count(n, 0);
    for (int j = 0; j < grid; ++j) count[d.sample((j + 0.5f) / grid)] += 1;
    for (size_t i = 0; i < n; ++i) {
      INFO("trial " << trial << ", item " << i << " of " << n << ", weight " << w[i]);
      if (w[i] == 0) REQUIRE(count[i] == 0);
      CHECK(count[i] / grid == Approx(w[i] / total).margin(double(n) / grid));
      CHECK(d.pmf(i) == Approx(w[i] / total));
    }
  }
}

TEST_CASE("AliasTable: one item, and no positive weight") {
  AliasTable one({2.5f});
  float pmf;
  CHECK(one.sample(0.999f, &pmf) == 0);
  CHECK(pmf == 1.0f);
  AliasTable none({0.0f, 0.0f});
  CHECK(none.total() == 0.0);
  CHECK(none.sample(0.7f, &pmf) < 2);
  CHECK(pmf == 0.0f);
}

TEST_CASE("sinCos2Pi matches libm's sin and cos of 2πu to 3e-7") {
  double worst = 0;
  auto check = [&](float u) {
    Vec2 sc = sinCos2Pi(u);
    double phi = 2 * M_PI * double(u);
    worst = std::max({worst, std::abs(sc.x - std::sin(phi)), std::abs(sc.y - std::cos(phi))});
  };
  for (int i = 0; i < 1000000; ++i) check(float(i) / 1000000.0f);
  for (float u : {0.0f, 0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, 0.99999994f}) check(u);
  CHECK(worst < 3e-7);
  // Exact at the quarter turns, where the polynomial's x is 0.
  CHECK(sinCos2Pi(0.25f).x == 1.0f);
  CHECK(sinCos2Pi(0.5f).y == -1.0f);
}

TEST_CASE("select and negateIf: branch-free ?: on floats, signed zeros and NaN included") {
  CHECK(select(true, 1.5f, -2.0f) == 1.5f);
  CHECK(select(false, 1.5f, -2.0f) == -2.0f);
  CHECK(std::signbit(select(true, -0.0f, 0.0f)));
  CHECK(std::isnan(select(false, 1.0f, NAN)));
  CHECK(negateIf(true, 3.0f) == -3.0f);
  CHECK(negateIf(false, 3.0f) == 3.0f);
  CHECK(std::signbit(negateIf(true, 0.0f)));
  CHECK(negateIf(true, -INFINITY) == INFINITY);
}

TEST_CASE("isFinite rejects any infinite or NaN component, accepts huge finite ones") {
  CHECK(isFinite(Vec3(1e38f, -1e38f, 3e38f)));
  CHECK(isFinite(Vec3(0.0f, -0.0f, 1e-45f)));
  CHECK_FALSE(isFinite(Vec3(INFINITY, 0, 0)));
  CHECK_FALSE(isFinite(Vec3(0, -INFINITY, 0)));
  CHECK_FALSE(isFinite(Vec3(0, 0, NAN)));
  CHECK_FALSE(isFinite(Vec3(INFINITY, -INFINITY, 0)));
}

TEST_CASE("uniform triangle sampling is uniform in area") {
  Rng rng(9, 9);
  // Split the triangle into 4 congruent sub-triangles by its edge midpoints: equal counts.
  std::vector<double> counts(4, 0), expected(4, 20000);
  for (int i = 0; i < 80000; ++i) {
    Vec2 b = sampleUniformTriangle(Vec2(rng.uniform(), rng.uniform()));
    float b2 = 1 - b.x - b.y;
    REQUIRE(b2 >= -1e-6f);
    int cell = b.x > 0.5f ? 0 : b.y > 0.5f ? 1 : b2 > 0.5f ? 2 : 3;
    counts[cell] += 1;
  }
  CHECK(test::chiSquarePValue(counts, expected) > 1e-3);
}
