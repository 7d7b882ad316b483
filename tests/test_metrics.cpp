#include <catch2/catch.hpp>

#include "core/rng.h"
#include "io/metrics.h"

using namespace pl;

TEST_CASE("error metrics against hand-computed values") {
  // One pixel of two... two pixels, six values: x = (1,2,3, 0,0,4), r = (1,1,1, 0,1,2).
  ImageRGB x(2, 1), r(2, 1);
  x.data = {1, 2, 3, 0, 0, 4};
  r.data = {1, 1, 1, 0, 1, 2};
  ErrorMetrics m = compareImages(x, r);
  // squared errors: 0 1 4 0 1 4 → sum 10
  CHECK(m.rmse == Approx(std::sqrt(10.0 / 6)));
  // relmse: 0 + 1/1.01 + 4/1.01 + 0 + 1/1.01 + 4/4.01
  CHECK(m.relmse == Approx((6.0 / 1.01 + 4.0 / 4.01) / 6));
  CHECK(m.mae == Approx(6.0 / 6));
  CHECK(m.meanRatio == Approx(10.0 / 6.0));
  ErrorMetrics same = compareImages(r, r);
  CHECK(same.rmse == 0);
  CHECK(same.relmse == 0);
  CHECK(same.meanRatio == 1);
}

TEST_CASE("relmse divides by r² + 0.01 - not r + 0.01") {
  ImageRGB x(1, 1), r(1, 1);
  x.data = {3, 3, 3};
  r.data = {2, 2, 2};
  CHECK(compareImages(x, r).relmse == Approx(1.0 / 4.01));
}

TEST_CASE("metrics refuse images of different sizes") {
  CHECK_THROWS_AS(compareImages(ImageRGB(2, 2), ImageRGB(2, 3)), Error);
}

TEST_CASE("relMSEFromHalves: two independent noisy halves give the relMSE their mean has against the truth") {
  // Truth r per value in [0, 2); each half is r plus independent uniform noise of variance
  // s²/3 (half-width s = 0.3·r + 0.05). Their mean has variance s²/6, so its expected relMSE is
  // Σ (s²/6)/(r² + 0.01)/n, computed here from r alone. The estimate divides by x² + 0.01
  // (x the mean, not r): with noise this small that differs by under 2%. 3·10⁵ values: the
  // estimate's own relative error is ~0.5% (the squared difference's relative sd √(4/5)/√n).
  const int W = 500, H = 200;
  ImageRGB a(W, H), b(W, H), truth(W, H);
  Rng rng(11, 3);
  double expected = 0;
  for (size_t i = 0; i < truth.data.size(); ++i) {
    const double r = 2.0 * rng.uniform(), s = 0.3 * r + 0.05;
    truth.data[i] = float(r);
    a.data[i] = float(r + s * (2 * rng.uniform() - 1));
    b.data[i] = float(r + s * (2 * rng.uniform() - 1));
    expected += s * s / 6 / (r * r + 0.01);
  }
  expected /= double(truth.data.size());
  const double estimate = relMSEFromHalves(a, b);
  CHECK(estimate == Approx(expected).epsilon(0.03));
  // And the mean's actual relMSE against the truth (compare's) agrees with both.
  ImageRGB mean(W, H);
  for (size_t i = 0; i < mean.data.size(); ++i) mean.data[i] = (a.data[i] + b.data[i]) / 2;
  CHECK(compareImages(mean, truth).relmse == Approx(expected).epsilon(0.03));
  CHECK_THROWS_AS(relMSEFromHalves(ImageRGB(2, 2), ImageRGB(2, 3)), Error);
}
