// The integrator registry: one declaration per parameter drives the CLI, TOML, fingerprint,
// metadata and README. These tests hold the derived places to the declarations.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "experiment/config.h"
#include "integrators/registry.h"

using namespace pl;
using Catch::Matchers::Contains;

namespace {

// A valid value different from the current one (or a value at all, for an unset parameter).
void changeParameter(ParamSet& p, const ParamSpec& s) {
  if (s.type == ParamType::Choice) {
    for (auto& c : s.choices)
      if (c != p.choice(s.name)) return p.setChoice(s.name, c);
    FAIL("choice parameter " << s.name << " has a single value");
  }
  double v = p.real(s.name);
  if (!p.isSet(s.name)) v = s.type == ParamType::Integer ? s.lo + 1 : (s.lo + std::min(s.hi, s.lo + 1.0)) / 2;
  else if (s.type == ParamType::Integer) v = v < s.hi ? v + 1 : v - 1;
  else v = v / 2 > s.lo ? v / 2 : (v + s.hi) / 2;
  p.setNumber(s.name, v);
}

}  // namespace

TEST_CASE("registry: every declared parameter of every integrator changes the reference-cache fingerprint") {
  // A parameter missing from the fingerprint would let a cached reference rendered with another
  // value pass for this one.
  size_t checked = 0;
  for (const IntegratorEntry* e : integrators()) {
    RunSettings base = RunSettings::of(e->name);
    base.image.width = base.image.height = 16;
    for (const ParamSpec& s : e->params) {
      INFO(e->name << "." << s.name);
      RunSettings changed = base;
      changeParameter(changed.params, s);
      CHECK(settingsFingerprint(changed) != settingsFingerprint(base));
      ++checked;
      if (s.budget) {  // unset (a time budget alone) is a value of its own too
        RunSettings unlimited = base;
        unlimited.params.unset(s.name);
        CHECK(settingsFingerprint(unlimited) != settingsFingerprint(base));
      }
    }
  }
  CHECK(checked >= 20);
}

TEST_CASE("registry: declarations are complete - a summary, a doc line, a valid default, a range that holds it") {
  for (const IntegratorEntry* e : integrators()) {
    INFO(e->name);
    CHECK(!e->summary.empty());
    CHECK(e->make);
    ParamSet p = e->defaults();
    for (const ParamSpec& s : e->params) {
      INFO(s.name);
      CHECK(!s.doc.empty());
      // Either a default, or words for what leaving it out means.
      CHECK((!s.defaultValue.empty() || !s.defaultDoc.empty()));
      if (s.defaultValue.empty()) continue;
      // The default passes its own validation.
      ParamSet q = e->defaults();
      if (s.type == ParamType::Choice) CHECK_NOTHROW(q.setChoice(s.name, s.defaultValue));
      else CHECK_NOTHROW(q.setNumber(s.name, p.real(s.name)));
    }
    // And the integrator can be made from its defaults.
    CHECK(makeIntegrator(e->name, p, RenderOptions{}) != nullptr);
  }
}

TEST_CASE("registry: a value out of range gets the same words from the CLI parser and from TOML") {
  ParamSet sppm = integratorEntry("sppm").defaults();
  std::string cli, toml;
  try {
    sppm.setText("alpha", "1.5");
  } catch (const Error& e) {
    cli = e.what();
  }
  try {
    sppm.setNumber("alpha", 1.5);
  } catch (const Error& e) {
    toml = e.what();
  }
  CHECK(cli == "must be in (0, 1], got 1.5");
  CHECK(cli == toml);
  CHECK_THROWS_WITH(sppm.setText("passes", "2.5"), "must be from 1 to 16777216, got 2.5");
  CHECK_THROWS_WITH(sppm.setText("passes", "12abc"), "must be an integer, got '12abc'");
  ParamSet photon = integratorEntry("photon").defaults();
  CHECK_THROWS_WITH(photon.setText("kernel", "gauss"), "unknown kernel 'gauss' (uniform, cone, epanechnikov, silverman)");
  CHECK_THROWS_WITH(photon.setText("photons", "4294967296"), Contains("must be from 0 to 4294967295"));
}

TEST_CASE("registry: README's parameter tables are the registry's (photonlab integrators --markdown)") {
  std::ifstream in(std::string(PHOTONLAB_SOURCE_DIR) + "/README.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string readme = ss.str();
  const std::string begin = "<!-- integrators:begin -->\n", end = "<!-- integrators:end -->";
  size_t b = readme.find(begin), e = readme.find(end);
  REQUIRE(b != std::string::npos);
  REQUIRE(e != std::string::npos);
  INFO("regenerate with: python3 scripts/readme_numbers.py --integrators");
  auto trimmed = [](std::string t) {
    while (!t.empty() && t.back() == '\n') t.pop_back();
    return t;
  };
  CHECK(trimmed(readme.substr(b + begin.size(), e - b - begin.size())) == trimmed(integratorsMarkdown()));
}
