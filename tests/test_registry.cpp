// The integrator registry: one declaration per parameter drives the CLI, TOML, fingerprint,
// metadata and the documentation. These tests hold the derived places to the declarations.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <sstream>

#include "experiment/config.h"
#include "integrators/builtins.h"
#include "integrators/progressive.h"
#include "integrators/registry.h"
#include "render/integrator.h"

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

TEST_CASE("registry: the documentation's parameter tables are the registry's (photonlab integrators --markdown)") {
  std::ifstream in(std::string(PHOTONLAB_SOURCE_DIR) + "/docs/pages/reference/integrators.md");
  REQUIRE(in);
  std::stringstream ss;
  ss << in.rdbuf();
  INFO("regenerate with: python3 scripts/docs_reference.py");
  // The built-ins (this test binary registers a test-only integrator too, which photonlab lacks).
  for (const IntegratorEntry& builtin : builtinIntegrators()) {
    INFO(builtin.name);
    CHECK(ss.str().find(integratorMarkdown(integratorEntry(builtin.name))) != std::string::npos);
  }
}

TEST_CASE("experiment keys: every documented key is one the parser accepts") {
  // One config holding every key experimentKeys() lists (the reference by integrator; its
  // `file` form is the one key that excludes the others, checked on its own below).
  const std::string scene = std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf";
  std::map<std::string, std::string> value = {
      {"name", "\"x\""}, {"description", "\"d\""}, {"scene", "\"" + scene + "\""}, {"units", "\"radiometric\""},
      {"env", "0.5"}, {"env_rotate", "10"}, {"env_scale", "2"}, {"width", "16"}, {"height", "16"}, {"threads", "1"},
      {"inset", "[0, 0, 4, 4]"}, {"exposure", "1"}, {"tonemap", "\"aces\""}, {"baseline", "\"r\""},
      {"target_relmse", "0.1"}};
  std::string top, reference = "[reference]\n", run = "[[run]]\n";
  for (const ConfigKey& k : experimentKeys()) {
    if (k.table.empty()) {
      if (k.key == "seeds" || k.key == "reference" || k.key == "run") continue;  // seed stands for both; tables below
      if (k.key == "seed") top += "seed = 3\n";
      else if (k.key == "provenance") continue;
      else {
        INFO(k.key);
        REQUIRE(value.count(k.key));
        top += k.key + " = " + value[k.key] + "\n";
      }
    } else if (k.table == "reference") {
      if (k.key == "integrator") reference += "integrator = \"path\"\n";
      else if (k.key == "seed") reference += "seed = 7\n";
      else CHECK(k.key == "file");
    } else if (k.table == "run") {
      if (k.key == "integrator") run += "integrator = \"path\"\n";
      else if (k.key == "label") run += "label = \"r\"\n";
      else if (k.key == "seed") run += "seed = 4\n";
      else if (k.key == "seeds") continue;  // either seed or seeds in one run
      else if (k.key == "time") run += "time = 1\n";
      else if (k.key == "spectral") run += "spectral = true\n";
      else FAIL("undocumented handling for run key " + k.key);
    }
  }
  const std::string text = top + "[provenance]\nnote = \"n\"\n" + reference + run;
  INFO(text);
  ExperimentConfig c = parseExperiment(text, "all-keys.toml");
  CHECK(c.runs.size() == 1);
  CHECK(c.runs[0].seeds == std::vector<uint64_t>{4});
  CHECK(int64_t(c.reference.settings.image.seed) == 7);
  // And a key the list does not hold is refused, the message listing the documented ones.
  CHECK_THROWS_WITH(parseExperiment(top + "colour = 1\n" + reference + run, "x.toml"),
                    Contains("colour: unknown key (known: name, description, scene, units"));
}

TEST_CASE("registry: each entry's declared family is the loop its integrator plugs into") {
  for (const IntegratorEntry* e : integrators()) {
    INFO(e->name << ": declared " << familyName(e->family));
    auto integrator = e->make(e->defaults(), RenderOptions{});
    const bool pixel = dynamic_cast<PixelIntegrator*>(integrator.get()) != nullptr;
    const bool pass = dynamic_cast<PassIntegrator*>(integrator.get()) != nullptr;
    const bool light = dynamic_cast<LightPathIntegrator*>(integrator.get()) != nullptr;
    CHECK((e->family == IntegratorFamily::Pixel) == pixel);
    CHECK((e->family == IntegratorFamily::Pass) == pass);
    CHECK((e->family == IntegratorFamily::LightPaths) == light);
    CHECK((e->family == IntegratorFamily::Own) == !(pixel || pass || light));
    CHECK(std::string(integrator->name()) == e->name);
  }
}

TEST_CASE("registry: a name is registered once, and a declaration is checked when it is registered") {
  const IntegratorEntry& path = integratorEntry("path");
  auto copy = [&](std::string name, std::vector<ParamSpec> params) {
    return IntegratorEntry(std::move(name), "test", IntegratorFamily::Pixel, "spp", std::move(params), path.make);
  };
  CHECK_THROWS_WITH(IntegratorRegistration(copy("path", path.params)), "integrator 'path' is registered twice");
  CHECK_THROWS_WITH(IntegratorRegistration(copy("twice", {params::spp(), params::spp()})),
                    "integrator twice: parameter 'spp' is declared twice");
  ParamSpec bad = params::maxDepth();
  bad.defaultValue = "-3";
  CHECK_THROWS_WITH(IntegratorRegistration(copy("bad-default", {bad})), Contains("the default of 'max_depth' is invalid"));
  ParamSpec budget = params::passes();
  CHECK_THROWS_WITH(IntegratorRegistration(copy("two-budgets", {params::spp(), budget})),
                    "integrator two-budgets: more than one budget parameter");
  IntegratorEntry refined = copy("refined", {params::spp(), params::sampler(8, "x", "y")});
  refined.refinement = {"photons"};
  CHECK_THROWS_WITH(IntegratorRegistration(refined),
                    "integrator refined: refinement parameter 'photons' is not a declared integer parameter");
  refined.refinement = {"sampler"};  // declared, but a choice: it cannot be doubled
  CHECK_THROWS_WITH(IntegratorRegistration(refined),
                    "integrator refined: refinement parameter 'sampler' is not a declared integer parameter");
  IntegratorEntry unrefinable = copy("unrefinable", {params::maxDepth()});
  CHECK_THROWS_WITH(IntegratorRegistration(unrefinable),
                    "integrator unrefinable: it estimates radiance but has neither a budget nor a refinement parameter");
  CHECK(findIntegrator("twice") == nullptr);
  CHECK(findIntegrator("two-budgets") == nullptr);
  CHECK(findIntegrator("refined") == nullptr);
}

TEST_CASE("registry: reading or setting a parameter the integrator does not declare throws") {
  ParamSet path = integratorEntry("path").defaults();
  CHECK_THROWS_WITH(path.real("alpha"), Contains("'alpha' is not a declared parameter (declared: spp, max_depth"));
  CHECK_THROWS_WITH(path.choice("kernel"), Contains("'kernel' is not a declared parameter"));
  CHECK_THROWS_WITH(path.setNumber("alpha", 0.5), Contains("'alpha' is not a declared parameter"));
  CHECK_THROWS_WITH(path.setText("radius", "1"), Contains("'radius' is not a declared parameter"));
  CHECK_THROWS_WITH(path.setChoice("kernel", "cone"), Contains("'kernel' is not a declared parameter"));
  CHECK_THROWS(path.resolve("radius", 1.0));
  // A declared one reads as before: its default, or 0 when unset.
  CHECK(path.integer("max_depth") == 64);
  ParamSet photon = integratorEntry("photon").defaults();
  CHECK(photon.real("radius") == 0.0);
}
