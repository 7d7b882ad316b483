// Time budgets: equal time must be equal. A render stops when its budget is spent wherever it
// is (photon tracing, the kd-tree build, the middle of a pass); what it has then is a correct
// estimate in every pixel it reached. The stop mechanisms are tested with an injected clock
// (core/budget.h, SteppingClock: every reading advances time by a fixed step, so that time is
// the work polled): what they assert holds on any machine at any load. One test measures the
// watchdog in real time; it is tagged [latency] (ctest label "latency": run serially, skipped
// by the sanitizer pass).
#include <catch2/catch.hpp>

#include <chrono>
#include <thread>

#include "core/budget.h"
#include "integrators/photon.h"
#include "photon/photon_tracer.h"
#include "integrators/progressive.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "integrator_helpers.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string scenePath(const char* name) { return std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/" + name; }

// A size×size render on one thread with a time budget alone, 1 s on `clock`.
RenderOptions clocked(int size, SteppingClock& clock) {
  RenderOptions ro;
  ro.width = ro.height = size;
  ro.spp = 0;
  ro.threads = 1;
  ro.timeLimit = 1.0;
  ro.clock = &clock;
  return ro;
}

}  // namespace

TEST_CASE("budget: expires when its time is spent - not while paused - never without a limit - at once on an interrupt") {
  // Steps of 1/8 s (exact in binary): the budget starts at reading 1 (t = 1/8), and its polls
  // read t = 2/8, 3/8, ...: elapsed 1/8 … 7/8 s at the first 7, the 1 s limit at the 8th.
  SteppingClock clock(0.125);
  Budget b(1.0, &clock);
  int polls = 0;  // polls that found time left
  while (!b.expired()) ++polls;
  CHECK(polls == 7);
  CHECK(b.timeUp());
  CHECK(b.expired());  // and stays so

  // Time inside excluding() counts neither in elapsed() nor against the limit: 100 readings
  // inside it, then the budget has seen two steps (the poll and this elapsed()).
  SteppingClock paused(0.125);
  Budget p(1.0, &paused);
  p.excluding([&] {
    for (int i = 0; i < 100; ++i) paused.seconds();
  });
  CHECK_FALSE(p.expired());
  CHECK(p.elapsed() == 0.375);
  polls = 0;
  while (!p.expired()) ++polls;
  CHECK(polls == 4);  // elapsed 0.5, 0.625, 0.75, 0.875; then 1.0 ends it

  SteppingClock forever(1000.0);
  Budget none(0.0, &forever);
  for (int i = 0; i < 100; ++i) REQUIRE_FALSE(none.expired());
  requestInterrupt();
  CHECK(none.expired());
  CHECK_FALSE(none.timeUp());
  clearInterrupt();
  CHECK_FALSE(none.expired());
}

TEST_CASE("budget: the steady clock's watchdog raises the flag at the deadline, not at a polling interval", "[latency]") {
  auto t0 = std::chrono::steady_clock::now();
  Budget b(0.2);
  CHECK_FALSE(b.expired());
  while (!b.expired() && secondsSince(t0) < 5) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  double at = secondsSince(t0);
  CHECK(b.timeUp());
  CHECK(at >= 0.2);
  CHECK(at < 0.3);
  CHECK(b.elapsed() >= 0.2);
  Budget p(0.2);
  p.excluding([] { std::this_thread::sleep_for(std::chrono::milliseconds(300)); });
  CHECK_FALSE(p.expired());
  CHECK(p.elapsed() < 0.1);
}

TEST_CASE("budget: photon tracing and the kd-tree build stop at their next poll after it - leaving nothing half-made") {
  auto scene = loadGltf(scenePath("cornell-box.gltf"));
  // Tracing polls once per chunk of 4096 paths: 100M paths would take a minute; a budget of 10
  // polls stops it after 10 chunks, with an empty, incomplete map (never used half-traced).
  {
    SteppingClock clock(1.0);
    Budget budget(10.0, &clock);
    PhotonTracingOptions o;
    o.globalPaths = 100000000;
    o.causticPaths = 0;
    o.threads = 1;
    o.budget = &budget;
    PhotonMaps maps = tracePhotons(*scene, o);
    CHECK_FALSE(maps.complete);
    CHECK(maps.global.size() == 0);
    CHECK(clock.readings() <= 12);  // the start, the 10 polls, the one that found it spent
  }
  // The build polls every 2¹⁶ point reads. An expired budget stops it at its first poll, and a
  // budget expiring half-way (by its polls) abandons the tree at that poll: the map stays empty.
  std::vector<Photon> photons;
  Rng rng(3, 3);
  for (int i = 0; i < 1000000; ++i)
    photons.push_back(Photon(Vec3(rng.uniform(), rng.uniform(), rng.uniform()), Vec3(0, 1, 0), Spectrum(1.0f),
                             Photon::kDirect, rng.uniform()));
  SteppingClock counting(1.0);
  uint64_t fullPolls = 0;
  {
    Budget unlimited(1e12, &counting);  // a limit never reached: every poll reads the clock
    PhotonMap full;
    std::vector<Photon> input = photons;
    REQUIRE(full.build(std::move(input), &unlimited));
    fullPolls = counting.readings() - 1;
  }
  INFO("a full build polls " << fullPolls << " times");
  REQUIRE(fullPolls >= 4);
  {
    SteppingClock clock(1.0);
    Budget spent(1.0, &clock);
    REQUIRE(spent.expired());
    const uint64_t before = clock.readings();
    PhotonMap map;
    std::vector<Photon> input = photons;
    CHECK_FALSE(map.build(std::move(input), &spent));
    CHECK(map.size() == 0);
    CHECK(clock.readings() == before);  // spent already: the flag alone stops it
  }
  {
    SteppingClock clock(1.0);
    Budget half(double(fullPolls / 2), &clock);
    PhotonMap map;
    std::vector<Photon> input = photons;
    CHECK_FALSE(map.build(std::move(input), &half));
    CHECK(map.size() == 0);
    CHECK(clock.readings() == fullPolls / 2 + 1);  // the start and the polls up to the deadline
  }
}

TEST_CASE("budget: the photon integrator stops inside its photon maps or its final gathers") {
  auto scene = loadGltf(scenePath("cornell-box.gltf"));
  // 1. Final gathering polls once per packet of 8 pixels: 512 packets per pass at 64×64. A budget
  // of 100 polls of 10 ms passes the photon maps' few polls and ends in the first pass.
  {
    auto pm = makeWith("photon", {{"photons", 20000}, {"caustic_photons", 20000}, {"final_gather", 4}});
    SteppingClock clock(0.01);
    RenderOptions ro = clocked(64, clock);
    RenderInfo st;
    ImageRGB img = render(*scene, *pm, ro, &st);
    INFO("stats " << st.seconds << " s, mean spp " << st.meanWork);
    CHECK(st.timeUp);
    CHECK(st.seconds >= 1.0);
    CHECK(st.spp == 0);  // not even one full pass ...
    CHECK(st.meanWork > 0);  // ... but some pixels have their sample
    CHECK(st.meanWork < 1);
  }
  // 2. Photon tracing: 30M paths, 7,300 chunks; a budget of 20 polls ends inside them.
  {
    auto pm = makeWith("photon", {{"photons", 30000000}, {"caustic_photons", 0}});
    SteppingClock clock(0.05);
    RenderOptions ro = clocked(16, clock);
    RenderInfo st;
    render(*scene, *pm, ro, &st);
    CHECK(st.timeUp);
    CHECK(st.meanWork == 0);
    REQUIRE(pm->warnings().size() == 1);
    CHECK(pm->warnings()[0].find("time budget ran out while the photon maps were traced") != std::string::npos);
  }
}

TEST_CASE("budget: path guiding's time budget covers training and photon tracing") {
  // A time budget alone: iterations double until the next would not fit, and the last runs until
  // the budget ends; the photon guide's map (20M paths for its first iteration, 4,900 chunks) is
  // cut short by the same budget. Either way the render returns with a finite image. Guided path
  // tracing polls once per pixel: 2,304 polls per sample at 48×48.
  auto scene = loadGltf(scenePath("cornell-box.gltf"));
  struct Case {
    const char* guide;
    double photons, polls;
  };
  for (const Case& c : {Case{"sdtree", 1e5, 2e4}, Case{"photons", 1e5, 2e4}, Case{"photons", 2e7, 200}}) {
    INFO(c.guide << ", " << c.photons << " photons, " << c.polls << " polls");
    SteppingClock clock(1.0 / c.polls);
    RenderOptions ro = clocked(48, clock);
    RenderInfo st;
    ImageRGB img = makeWith("guided", {{"photons", c.photons}}, ro, {{"guide", c.guide}})->render(*scene, ro, &st);
    INFO(st.meanWork << " spp on average");
    CHECK(st.timeUp);
    for (float v : img.data) REQUIRE(std::isfinite(v));
    // It rendered, not only trained; with the map cut short, guiding renders nothing at all.
    if (c.photons <= 1e5) CHECK(st.meanWork >= 1);
    if (c.photons > 1e5) CHECK(clock.readings() < 2 * c.polls);
  }
}

TEST_CASE("budget: a pass cut short leaves every pixel it reached exactly its n + 1-pass estimate - the others their n-pass one") {
  // When the budget ends a pass half-way through its pixels, the pixels it reached have one pass
  // (or sample) more than the others, and each divides by its own count. Streams are keyed by
  // (seed, pixel, pass), so each pixel of the cut render must equal, bit for bit, the same pixel
  // of an uncut render with n passes or of one with n + 1. A common divisor would make the
  // reached pixels (n + 1)/n too bright and match neither. Budgets are tried until one ends
  // inside a pass (the pixels' mean count is then fractional).
  // With an injected clock (0.1 ms per poll, one thread) the budgets are counts of polled packets
  // of pixels, so where each ends is the same on every machine.
  auto scene = loadGltf(scenePath("cornell-box.gltf"));
  auto same = [](const ImageRGB& a, const ImageRGB& b, size_t i) {
    return a.data[3 * i] == b.data[3 * i] && a.data[3 * i + 1] == b.data[3 * i + 1] && a.data[3 * i + 2] == b.data[3 * i + 2];
  };
  for (const char* name : {"ppm", "sppm", "pppm", "path"}) {
    INFO(name);
    const bool progressive = std::string(name) != "path";
    RenderOptions ro;
    ro.width = ro.height = 96;
    auto renderWith = [&](double limit, int work, double* mean) {
      SteppingClock clock(1e-4);
      if (progressive) {
        RenderOptions r = ro;
        r.timeLimit = limit;
        r.threads = 1;
        r.clock = &clock;
        RenderInfo info;
        std::map<std::string, double> p = {{"photons_per_pass", 20000}};
        if (work != INT32_MAX) p["passes"] = work;  // else unset: until the budget ends
        ImageRGB img = makeWith(name, p)->render(*scene, r, &info);
        *mean = info.meanWork;
        return img;
      }
      RenderOptions r = ro;
      r.spp = work;
      r.timeLimit = limit;
      r.threads = 1;
      r.clock = &clock;
      RenderInfo st;
      auto path = makeIntegrator("path", {});
      ImageRGB img = render(*scene, *path, r, &st);
      *mean = st.meanWork;
      return img;
    };
    bool cut = false;
    for (double limit = 0.3; limit < 3 && !cut; limit += 0.13) {
      double mean = 0;
      ImageRGB img = renderWith(limit, progressive ? INT32_MAX : 0, &mean);
      const int n = int(mean);
      if (mean == n || n < 1) continue;  // ended between passes: try another budget
      double ignored;
      ImageRGB a = renderWith(0, n, &ignored), b = renderWith(0, n + 1, &ignored);
      // Pixels whose n- and n + 1-pass estimates are the same bits (the black rows above the
      // box's opening, where every sample is 0) cannot tell which they have: a pass cut short
      // within them (CI once stopped 90 pixels into the top rows) is tried again.
      size_t asA = 0, asB = 0, neither = 0, ambiguous = 0;
      for (size_t i = 0; i < size_t(ro.width) * ro.height; ++i) {
        if (same(a, b, i)) ++ambiguous;
        else if (same(img, a, i)) ++asA;
        else if (same(img, b, i)) ++asB;
        else ++neither;
      }
      INFO("budget " << limit << " s: mean passes " << mean << "; pixels as n = " << n << ": " << asA
                     << ", as n + 1: " << asB << ", neither: " << neither << ", the same either way: " << ambiguous);
      CHECK(neither == 0);
      cut = asB > 0 && asA > 0;
    }
    CHECK(cut);
  }
}
