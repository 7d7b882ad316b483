#include <catch2/catch.hpp>

#include <cmath>

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

TEST_CASE("Distribution1D: the branch-free count (up to 16 items) and the binary search agree") {
  // The same weights repeated: 8 items use the count, 32 the search; item i of the short
  // list must come out where items i, i + 8, i + 16, i + 24 of the long one do, for u and u/4.
  std::vector<float> w = {0.5f, 0.0f, 2.0f, 1.0f, 0.25f, 3.0f, 0.0f, 1.25f}, w4;
  for (int k = 0; k < 4; ++k) w4.insert(w4.end(), w.begin(), w.end());
  Distribution1D small(w), large(w4);
  Rng rng(4, 4);
  for (int i = 0; i < 20000; ++i) {
    float u = rng.uniform(), pmfSmall, pmfLarge, uSmall, uLarge;
    size_t a = small.sample(u, &pmfSmall, &uSmall);
    size_t b = large.sample(u / 4, &pmfLarge, &uLarge);
    REQUIRE(a == b);
    REQUIRE(w[a] > 0.0f);
    CHECK(pmfSmall == Approx(4 * pmfLarge));
    CHECK(uSmall == Approx(uLarge).margin(1e-5));
  }
  CHECK(small.pmf(2) == Approx(2.0 / 8.0));
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
