// Renders split into slices (`photonlab render --sample-range`, `--pass-range`) and merged
// (`photonlab merge`): the exact accumulator they rest on, then the command line: any split of
// a render merges into its bits, and slices that do not belong together are refused.
#include <catch2/catch.hpp>
#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "core/exact_sum.h"
#include "render/film.h"
#include "cli_helpers.h"
#include "gltf_fixture.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

// `photonlab compare` prints rmse 0 only when every pixel is the same float.
bool identical(const std::string& a, const std::string& b) {
  Result r = run("compare " + a + " " + b);
  return r.code == 0 && r.out.find("\"rmse\": 0,") != std::string::npos;
}

const std::string kScene = std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf";

}  // namespace

TEST_CASE("ExactSum: any grouping of a sum gives the same bits, rounded once to the nearest double") {
  // Floats over 40 binary orders of magnitude, both signs: the exact sum spans more than a
  // double's 53 bits, so double accumulation depends on the order (checked below, so the test
  // means something), while the exact sums of any split agree to the bit. The reference value
  // is the sum in __float128 (113 bits: exact for this span and count), rounded to double.
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
  std::uniform_int_distribution<int> exponent(-20, 20);
  std::vector<float> values(20000);
  for (float& v : values) v = std::ldexp(mantissa(gen), exponent(gen)) * (gen() % 5 == 0 ? -1.0f : 1.0f);
  __float128 reference = 0;
  for (float v : values) reference += v;
  ExactSum whole;
  double forward = 0, backward = 0;
  for (float v : values) whole.add(v), forward += v;
  for (auto it = values.rbegin(); it != values.rend(); ++it) backward += *it;
  CHECK(forward != backward);  // double accumulation depends on the order
  CHECK(whole.value() == double(reference));
  for (size_t split : {size_t(1), size_t(777), size_t(10000), size_t(19999)}) {
    ExactSum a, b, c;
    for (size_t i = 0; i < split; ++i) a.add(values[i]);
    for (size_t i = split; i < values.size(); ++i) b.add(values[i]);
    c.add(b), c.add(a);  // the other order of the two slices
    a.add(b);
    CHECK(a == whole);
    CHECK(c == whole);
  }
  // Edge values: subnormals, the largest float, cancellation to zero, a tie to even.
  ExactSum e;
  e.add(std::numeric_limits<float>::denorm_min());
  CHECK(e.value() == double(std::numeric_limits<float>::denorm_min()));
  e.add(-std::numeric_limits<float>::denorm_min());
  CHECK(e.value() == 0.0);
  ExactSum big;
  for (int i = 0; i < 4; ++i) big.add(std::numeric_limits<float>::max());
  CHECK(big.value() == 4.0 * double(std::numeric_limits<float>::max()));
  ExactSum tie;  // 2^53 + 1 is halfway between two doubles: rounds to the even one, 2^53
  tie.add(std::ldexp(1.0f, 53));
  tie.add(1.0f);
  CHECK(tie.value() == std::ldexp(1.0, 53));
  tie.add(std::ldexp(1.0f, -30));  // just above the halfway point: rounds up
  CHECK(tie.value() == std::ldexp(1.0, 53) + 2.0);
}

TEST_CASE("ExactSum: rounding to double sees every bit, at every position of the 320") {
  // 1. Sums over a 60-bit span centred anywhere in float's range, against __float128 (113 bits:
  //    exact for that span and 2000 terms), so the rounded 64-bit window and the bits below it
  //    fall at every offset within and across the 64-bit limbs.
  std::mt19937 gen(23);
  std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
  std::uniform_int_distribution<int> spread(-30, 30);
  for (int centre = -110; centre <= 90; centre += 7) {
    __float128 reference = 0;
    ExactSum s;
    for (int i = 0; i < 2000; ++i) {
      const float v = std::ldexp(mantissa(gen), centre + spread(gen)) * (gen() % 3 == 0 ? -1.0f : 1.0f);
      reference += v;
      s.add(v);
    }
    REQUIRE(s.value() == double(reference));
  }
  // 2. A tie between two doubles, broken by one bit anywhere below, however far. 2^e + 2^(e−53)
  //    lies halfway between 2^e and its successor 2^e + 2^(e−52): alone it rounds to the even
  //    one, 2^e; with 2^t added (t < e − 53) it is above halfway and rounds up; with 2^t taken
  //    away, below halfway and down. IEEE's rule, not this class, gives the expected values.
  int checked = 0;
  for (int e = -95; e <= 127; e += 3)
    for (int t = -149; t < e - 53; t += 4)
      for (float sign : {1.0f, -1.0f}) {
        const double base = std::ldexp(1.0, e), up = base + std::ldexp(1.0, e - 52);
        ExactSum tie;
        tie.add(sign * std::ldexp(1.0f, e)), tie.add(sign * std::ldexp(1.0f, e - 53));
        REQUIRE(tie.value() == sign * base);
        ExactSum above = tie, below = tie;
        above.add(sign * std::ldexp(1.0f, t));
        below.add(-sign * std::ldexp(1.0f, t));
        REQUIRE(above.value() == sign * up);
        REQUIRE(below.value() == sign * base);
        ++checked;
      }
  CHECK(checked > 4000);
}

TEST_CASE("ExactSum: carries and borrows cross every limb boundary exactly") {
  // Every float exponent, both signs, alone and in pairs whose exact sum a double holds (two
  // floats within 2^28 of each other span at most 52 bits): the sum must be that double, and
  // adding the negations must return every limb to zero. Pairs of opposite signs across a
  // 64-bit limb boundary borrow; a negative value on an empty sum borrows through every limb.
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
  auto zero = [](const ExactSum& s) {
    for (int i = 0; i < ExactSum::kLimbs; ++i)
      if (s.limbs()[i] != 0) return false;
    return true;
  };
  int checked = 0;
  for (int ea = -149; ea <= 127; ++ea)
    for (int d = 0; d <= 28 && ea - d >= -149; d += 7) {
      const float a = std::ldexp(mantissa(gen), ea) * (gen() % 2 ? -1.0f : 1.0f);
      const float b = std::ldexp(ea - d < -126 ? 1.0f : mantissa(gen), ea - d) * (gen() % 2 ? -1.0f : 1.0f);
      if (!std::isfinite(a) || !std::isfinite(b) || a == 0.0f || b == 0.0f) continue;
      ExactSum s;
      s.add(a);
      REQUIRE(s.value() == double(a));
      s.add(b);
      REQUIRE(s.value() == double(a) + double(b));
      s.add(-a), s.add(-b);
      REQUIRE(zero(s));
      ExactSum n;  // negative first: the borrow runs through all five limbs, then the carry back
      n.add(-b), n.add(b);
      REQUIRE(zero(n));
      ++checked;
    }
  CHECK(checked > 1000);
}

TEST_CASE("SplatFilm: each pixel's sums are its splats' exact sums, whatever the threads and buffers") {
  // SplatFilm::add groups a band's splats by blocks of pixels before adding them; the expected
  // sums are made here splat by splat in the buffers' order, straight into per-pixel ExactSums.
  // Films whose pixel count is no multiple of the block or of the thread count, and whose bands
  // start and end inside a block; splats on the first and last pixel, repeated pixels, signs.
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> value(-2.0f, 3.0f);
  for (const auto& [W, H] : {std::pair{37, 29}, {600, 500}}) {
    const size_t pixels = size_t(W) * H;
    std::vector<SplatBuffer> buffers(7);
    std::vector<ExactSum> expected(pixels * 3);
    for (size_t k = 0; k < buffers.size(); ++k)
      for (int i = 0; i < 20000; ++i) {
        const size_t pixel = i == 0 ? 0 : i == 1 ? pixels - 1 : k == 3 ? size_t(gen() % 7) : size_t(gen() % pixels);
        const Spectrum v(value(gen), value(gen), value(gen));
        buffers[k].add(Vec2(float(pixel % size_t(W)) + 0.5f, float(pixel / size_t(W)) + 0.5f), W, v);
        for (int ch = 0; ch < 3; ++ch) expected[pixel * 3 + size_t(ch)].add(v[ch]);
      }
    for (int threads : {1, 2, 3}) {
      INFO(W << "x" << H << ", " << threads << " threads");
      SplatFilm film(W, H);
      film.add(std::vector<SplatBuffer>(buffers.begin(), buffers.begin() + 4), threads);  // in two calls
      film.add(std::vector<SplatBuffer>(buffers.begin() + 4, buffers.end()), threads);
      size_t wrong = 0;
      for (size_t i = 0; i < pixels * 3; ++i) wrong += !(film.sums()[i] == expected[i]);
      CHECK(wrong == 0);
    }
  }
}

TEST_CASE("slices: any split of a render merges into its bits (path by samples, pppm by passes)", "[heavy]") {
  const std::string dir = GltfFixture::dir();
  SECTION("path tracer, 12 samples as 0:5, 5:6, 6:12, merged in another order - with either sampler") {
    const std::string sampler = GENERATE(as<std::string>{}, "independent", "sobol");
    INFO(sampler);
    const std::string common = "render " + kScene + " --integrator path --spp 12 --width 24 -q --sampler " + sampler;
    REQUIRE(run(common + " -o " + dir + "/whole.exr").code == 0);
    REQUIRE(run(common + " --sample-range 0:5 -o " + dir + "/s0.exr").code == 0);
    REQUIRE(run(common + " --sample-range 5:6 -o " + dir + "/s1.exr").code == 0);
    REQUIRE(run(common + " --sample-range 6:12 -o " + dir + "/s2.exr").code == 0);
    REQUIRE(run("merge " + dir + "/s2.exr " + dir + "/s0.exr " + dir + "/s1.exr -o " + dir + "/merged.exr").code == 0);
    CHECK(identical(dir + "/merged.exr", dir + "/whole.exr"));
    // Merging merged slices (--partial) is the same.
    REQUIRE(run("merge " + dir + "/s0.exr " + dir + "/s1.exr --partial -o " + dir + "/s01.exr").code == 0);
    REQUIRE(run("merge " + dir + "/s01.exr " + dir + "/s2.exr -o " + dir + "/merged2.exr").code == 0);
    CHECK(identical(dir + "/merged2.exr", dir + "/whole.exr"));
    // A slice alone is not the whole.
    REQUIRE(run("merge " + dir + "/s0.exr -o " + dir + "/first.exr").code == 0);
    CHECK_FALSE(identical(dir + "/first.exr", dir + "/whole.exr"));
  }
  SECTION("pppm, 6 passes as 0:2, 2:3, 3:6, and as 0:6:3, 1:6:3, 2:6:3 (each pass with the whole render's radius)") {
    const std::string common = "render " + kScene + " --integrator pppm --passes 6 --photons-per-pass 5000 --width 24 -q";
    REQUIRE(run(common + " -o " + dir + "/pwhole.exr").code == 0);
    REQUIRE(run(common + " --pass-range 0:2 -o " + dir + "/p0.exr").code == 0);
    REQUIRE(run(common + " --pass-range 2:3 -o " + dir + "/p1.exr").code == 0);
    REQUIRE(run(common + " --pass-range 3:6 -o " + dir + "/p2.exr").code == 0);
    REQUIRE(run("merge " + dir + "/p1.exr " + dir + "/p2.exr " + dir + "/p0.exr -o " + dir + "/pmerged.exr").code == 0);
    CHECK(identical(dir + "/pmerged.exr", dir + "/pwhole.exr"));
    // Interleaved: every third pass from 0, 1 and 2 (each slice walks the radius schedule).
    for (int k = 0; k < 3; ++k)
      REQUIRE(run(common + " --pass-range " + std::to_string(k) + ":6:3 -o " + dir + "/i" + std::to_string(k) + ".exr").code == 0);
    REQUIRE(run("merge " + dir + "/i2.exr " + dir + "/i0.exr " + dir + "/i1.exr -o " + dir + "/imerged.exr").code == 0);
    CHECK(identical(dir + "/imerged.exr", dir + "/pwhole.exr"));
    Result r = run("merge " + dir + "/i0.exr " + dir + "/i1.exr -o " + dir + "/none.exr");
    CHECK(r.code == 1);
    CHECK_THAT(r.err, Contains("passes 2:3 are in none of the slices"));
  }
}

TEST_CASE("slices: the light-side integrators' iterations merge into their bits too (light, bdpt, vcm)") {
  // Light tracing splats; bdpt and vcm add splats and camera-side sums (vcm's merge radius
  // follows the iteration index, so each slice's iterations use the whole render's radii).
  const std::string dir = GltfFixture::dir();
  for (const char* integrator : {"light", "bdpt", "vcm"}) {
    INFO(integrator);
    const std::string common = "render " + kScene + " --integrator " + integrator + " --spp 6 --width 16 -q";
    REQUIRE(run(common + " -o " + dir + "/lwhole.exr").code == 0);
    REQUIRE(run(common + " --sample-range 0:6:2 -o " + dir + "/l0.exr").code == 0);
    REQUIRE(run(common + " --sample-range 1:4:2 -o " + dir + "/l1.exr").code == 0);
    REQUIRE(run(common + " --sample-range 5:6 -o " + dir + "/l2.exr").code == 0);
    REQUIRE(run("merge " + dir + "/l2.exr " + dir + "/l1.exr " + dir + "/l0.exr -o " + dir + "/lmerged.exr").code == 0);
    CHECK(identical(dir + "/lmerged.exr", dir + "/lwhole.exr"));
  }
}

TEST_CASE("slices: what does not belong together is one line, exit 1, and no output") {
  const std::string dir = GltfFixture::dir();
  const std::string common = "render " + kScene + " --integrator path --spp 8 --width 16 -q";
  REQUIRE(run(common + " --sample-range 0:4 -o " + dir + "/a.exr").code == 0);
  REQUIRE(run(common + " --sample-range 2:6 -o " + dir + "/b.exr").code == 0);
  REQUIRE(run(common + " --sample-range 6:8 -o " + dir + "/c.exr").code == 0);
  REQUIRE(run(common + " --sample-range 4:6 --seed 2 -o " + dir + "/d.exr").code == 0);
  REQUIRE(run(common + " -o " + dir + "/whole.exr").code == 0);
  auto refused = [&](const std::string& args, const std::string& mentions) {
    fs::remove(dir + "/out.exr");
    Result r = run(args);
    INFO(args << "\n" << r.err);
    CHECK(r.code == 1);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_THAT(r.err, Contains(mentions));
    CHECK_FALSE(fs::exists(dir + "/out.exr"));
  };
  refused("merge " + dir + "/a.exr " + dir + "/b.exr -o " + dir + "/out.exr", "overlaps");
  refused("merge " + dir + "/a.exr " + dir + "/c.exr -o " + dir + "/out.exr", "samples 4:6 are in none of the slices");
  refused("merge " + dir + "/a.exr " + dir + "/d.exr -o " + dir + "/out.exr", "(seed 2 against 1)");
  refused("merge " + dir + "/a.exr " + dir + "/whole.exr -o " + dir + "/out.exr", "whole.exr: not a render slice");
  refused("merge " + dir + "/a.exr " + dir + "/none.exr -o " + dir + "/out.exr", "none.exr: no such file");
  refused(common + " --sample-range 4:2 -o " + dir + "/out.exr", "--sample-range: expected A:B or A:B:K with 0 <= A < B");
  refused(common + " --sample-range 0:9 -o " + dir + "/out.exr", "reaches past --spp 8");
  refused(common + " --sample-range 0:4 --time 1 -o " + dir + "/out.exr", "not a time");
  refused(common + " --sample-range 0:4 -o " + dir + "/out.png", "a slice is written as .exr");
  refused(common + " --pass-range 0:4 -o " + dir + "/out.exr", "--pass-range: only with pppm");
  refused("render " + kScene + " --integrator sppm --passes 4 --width 16 -q --pass-range 0:2 -o " + dir + "/out.exr",
          "--pass-range: only with pppm");
}
