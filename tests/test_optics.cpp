#include <catch2/catch.hpp>

#include "optics/optics.h"

using namespace pl;

TEST_CASE("reflect: R = 2(N·L)N − L keeps the angle and the plane of incidence") {
  Vec3 N(0, 0, 1);
  Vec3 L = glm::normalize(Vec3(0.3f, -0.4f, 0.8f));
  Vec3 R = reflect(L, N);
  CHECK(R.x == Approx(-L.x));
  CHECK(R.y == Approx(-L.y));
  CHECK(R.z == Approx(L.z));
  CHECK(glm::length(R) == Approx(1.0f));
  // Tilted normal: angle of incidence equals angle of reflection, and L, N, R are coplanar.
  Vec3 N2 = glm::normalize(Vec3(1, 2, 3));
  Vec3 R2 = reflect(L, N2);
  CHECK(glm::dot(R2, N2) == Approx(glm::dot(L, N2)));
  CHECK(glm::dot(glm::cross(L, N2), R2) == Approx(0.0f).margin(1e-6));
}

TEST_CASE("refract obeys Snell's law η_i sinθ_i = η_t sinθ_t") {
  Vec3 n(0, 0, 1);
  for (float eta : {1.33f, 1.5f, 2.4f, 1.0f / 1.5f}) {
    for (float thetaDeg : {0.0f, 10.0f, 30.0f, 40.0f}) {
      float theta = glm::radians(thetaDeg);
      Vec3 wi(std::sin(theta), 0, std::cos(theta));
      Vec3 wt;
      REQUIRE(refract(wi, n, eta, &wt));
      float sinT = std::sqrt(wt.x * wt.x + wt.y * wt.y);
      CHECK(std::sin(theta) == Approx(eta * sinT).margin(1e-5));
      CHECK(wt.z < 0);                  // the other side of the interface
      CHECK(wt.x * wi.x <= 0);          // bends on the other side of the normal
      CHECK(glm::length(wt) == Approx(1.0f));
    }
  }
}

TEST_CASE("total internal reflection exactly past the critical angle") {
  float eta = 1.0f / 1.5f;  // glass to air
  float critical = std::asin(eta);
  Vec3 n(0, 0, 1), wt;
  auto dir = [](float t) { return Vec3(std::sin(t), 0, std::cos(t)); };
  CHECK(refract(dir(critical - 1e-3f), n, eta, &wt));
  CHECK_FALSE(refract(dir(critical + 1e-3f), n, eta, &wt));
  CHECK(fresnelDielectric(std::cos(critical + 1e-3f), eta) == 1.0f);
  CHECK(fresnelDielectric(std::cos(critical - 1e-2f), eta) < 1.0f);
}

TEST_CASE("Fresnel at normal and grazing incidence") {
  // Normal incidence: R0 = ((η−1)/(η+1))², the same from either side.
  for (float eta : {1.5f, 1.33f, 2.0f}) {
    float R0 = ((eta - 1) / (eta + 1)) * ((eta - 1) / (eta + 1));
    CHECK(fresnelDielectric(1.0f, eta) == Approx(R0).epsilon(1e-5));
    CHECK(fresnelDielectric(-1.0f, eta) == Approx(R0).epsilon(1e-5));
    CHECK(fresnelDielectric(1.0f, 1.0f / eta) == Approx(R0).epsilon(1e-5));
  }
  CHECK(fresnelDielectric(1.0f, 1.5f) == Approx(0.04f).epsilon(1e-4));
  // Grazing (90°): everything is reflected.
  CHECK(fresnelDielectric(0.0f, 1.5f) == Approx(1.0f));
  CHECK(fresnelDielectric(1e-4f, 1.5f) > 0.99f);
  // Schlick: F0 at normal incidence, 1 at grazing.
  CHECK(fresnelSchlick(Spectrum(0.3f), 1.0f).r == Approx(0.3f));
  CHECK(fresnelSchlick(Spectrum(0.3f), 0.0f).g == Approx(1.0f));
  // Brewster angle: p-polarised reflectance vanishes, so F = rs²/2 there.
  float eta = 1.5f, thetaB = std::atan(eta), ct = std::cos(std::asin(std::sin(thetaB) / eta));
  float rs = (std::cos(thetaB) - eta * ct) / (std::cos(thetaB) + eta * ct);
  CHECK(fresnelDielectric(std::cos(thetaB), eta) == Approx(0.5f * rs * rs).epsilon(1e-4));
}
