#include <catch2/catch.hpp>

#include "core/rng.h"
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

TEST_CASE("Distribution1D picks items in proportion to their weights") {
  Distribution1D d({1.0f, 0.0f, 3.0f});
  CHECK(d.pmf(0) == Approx(0.25));
  CHECK(d.pmf(1) == 0.0f);
  std::vector<double> counts(3, 0);
  Rng rng(3, 3);
  for (int i = 0; i < 40000; ++i) counts[d.sample(rng.uniform())] += 1;
  CHECK(counts[1] == 0);
  CHECK(counts[0] / 40000 == Approx(0.25).margin(0.01));
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
