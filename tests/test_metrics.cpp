#include <catch2/catch.hpp>

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
