// Experiment configs: what a valid file means (defaults, budgets, seeds, paths), and that every
// mistake is an error naming the file, the line and the key, before anything renders.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "experiment/config.h"
#include "photon/kernels.h"
#include "integrators/progressive.h"
#include "gltf_fixture.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

// A config in the fixture folder, next to a valid scene "scene.gltf".
struct ConfigFixture {
  std::string dir = GltfFixture::dir() + "/experiment";
  ConfigFixture() {
    fs::create_directories(dir);
    GltfFixture f;
    fs::copy_file(f.write("experiment-scene.gltf"), dir + "/scene.gltf", fs::copy_options::overwrite_existing);
  }
  std::string path() const { return dir + "/exp.toml"; }
  ExperimentConfig parse(const std::string& text) const { return parseExperiment(text, path()); }
  // The message of the Error parsing `text` throws.
  std::string error(const std::string& text) const {
    try {
      parse(text);
    } catch (const Error& e) {
      return e.what();
    }
    FAIL("no error for:\n" << text);
    return "";
  }
};

const std::string kHead = R"(name = "t"
scene = "scene.gltf"
width = 32
[reference]
integrator = "path"
spp = 64
)";

}  // namespace

TEST_CASE("experiment config: values - defaults - budgets - seeds - relative paths") {
  ConfigFixture f;
  auto c = f.parse(kHead + R"(
[[run]]
label = "SPPM"
integrator = "sppm"
time = 2.5
alpha = 0.5
photons_per_pass = 1000
seeds = [3, 4]
[[run]]
integrator = "photon"
spp = 4
k = 20
kernel = "cone"
final_gather = 0
radius = 0.05
[[run]]
integrator = "path"
)");
  CHECK(c.name == "t");
  CHECK(c.scene == fs::path(f.dir + "/scene.gltf").lexically_normal().string());
  CHECK(c.width == 32);
  CHECK(c.height == 0);  // from the camera once the scene is loaded
  REQUIRE(c.runs.size() == 3);
  const auto& sppm = c.runs[0].settings;
  CHECK(sppm.integrator == "sppm");
  CHECK(sppm.image.timeLimit == 2.5);
  CHECK(progressiveOptions(sppm.params).passes == INT32_MAX);  // time alone: as many passes as fit
  CHECK(progressiveOptions(sppm.params).alpha == 0.5);
  CHECK(progressiveOptions(sppm.params).photonsPerPass == 1000);
  CHECK(c.runs[0].seeds == std::vector<uint64_t>{3, 4});
  const auto& photon = c.runs[1].settings;
  CHECK(photon.renderOptions().spp == 4);
  CHECK(photon.params.integer("k") == 20);
  CHECK(parseKernel(photon.params.choice("kernel")) == Kernel::Cone);
  CHECK(photon.params.real("radius") == Approx(0.05f));
  CHECK(photon.params.integer("final_gather") == 0);
  CHECK(c.runs[1].label == "photon 2");  // default label
  CHECK(c.runs[1].seeds == std::vector<uint64_t>{1});
  CHECK(c.runs[2].settings.renderOptions().spp == RenderOptions().spp);  // no budget: the CLI's default
  CHECK(c.reference.settings.renderOptions().spp == 64);
  CHECK(c.reference.settings.image.width == 32);
}

TEST_CASE("experiment config: display and report keys - exposure - tonemap - baseline - target_relmse") {
  ConfigFixture f;
  auto c = f.parse("exposure = -1.5\ntonemap = \"aces\"\nbaseline = \"B\"\ntarget_relmse = 0.01\n" + kHead +
                   "[[run]]\nlabel = \"A\"\nintegrator = \"path\"\n[[run]]\nlabel = \"B\"\nintegrator = \"sppm\"\n");
  CHECK(c.display.exposure == -1.5);
  CHECK(c.display.curve == ToneCurve::ACES);
  CHECK(c.baseline == "B");
  CHECK(c.targetRelmse == 0.01);
  auto again = f.parse(resolvedConfigToml(c, {}));  // written out and read back
  CHECK(again.display.exposure == -1.5);
  CHECK(again.display.curve == ToneCurve::ACES);
  CHECK(again.baseline == "B");
  CHECK(again.targetRelmse == 0.01);
  // Defaults: no exposure change, clamping, the first run as the baseline (written out).
  auto d = f.parse(kHead + "[[run]]\nlabel = \"A\"\nintegrator = \"path\"\n");
  CHECK(d.display.isDefault());
  CHECK(resolvedConfigToml(d, {}).find("baseline = 'A'") != std::string::npos);
}

TEST_CASE("experiment config: the reference draws from seed -1 - no run can - an explicit one a run uses is refused") {
  ConfigFixture f;
  // Default: its own stream, −1, whatever the runs' seeds (before: the experiment's first seed).
  auto c = f.parse("seeds = [1, 2]\n" + kHead + "[[run]]\nintegrator = \"path\"\n");
  CHECK(c.reference.settings.image.seed == kReferenceSeed);
  CHECK(seedString(kReferenceSeed) == "-1");
  CHECK(resolvedConfigToml(c, {}).find("seed = -1") != std::string::npos);  // and it round-trips
  CHECK(f.parse(resolvedConfigToml(c, {})).reference.settings.image.seed == kReferenceSeed);
  // Explicit: any seed no run uses, negative ones included.
  CHECK(f.parse(kHead + "seed = 9\n[[run]]\nintegrator = \"path\"\nseeds = [1, 2]\n").reference.settings.image.seed == 9);
  CHECK(f.parse(kHead + "seed = -5\n[[run]]\nintegrator = \"path\"\n").reference.settings.image.seed == uint64_t(-5));
  std::string e = f.error(kHead + "seed = 7\n[[run]]\nintegrator = \"path\"\n[[run]]\nintegrator = \"path\"\nseeds = [3, 7]\n");
  CHECK_THAT(e, Contains(f.path() + ":7: reference.seed: seed 7 is also a seed of run[2]"));
  // Run seeds are 0 or more.
  CHECK_THAT(f.error(kHead + "[[run]]\nintegrator = \"path\"\nseed = -1\n"), Contains("run[1].seed: must be from 0"));
}

TEST_CASE("experiment config: mistakes name the file - line and key") {
  ConfigFixture f;
  const std::string p = f.path();
  // kHead is 6 lines; the [[run]] table starts on line 7.
  struct Case {
    std::string text, mentions;
  } cases[] = {
      {kHead + "[[run]]\nintegrator = \"path\"\nspq = 4\n", p + ":9: run[1].spq: unknown key"},
      {kHead + "[[run]]\nintegrator = \"path\"\nspp = \"many\"\n", p + ":9: run[1].spp: must be an integer"},
      {kHead + "[[run]]\nintegrator = \"path\"\nspp = 0\n", p + ":9: run[1].spp: must be from 1"},
      {kHead + "[[run]]\nintegrator = \"path\"\nalpha = 0.5\n", p + ":9: run[1].alpha: is not a parameter of integrator path"},
      {kHead + "[[run]]\nintegrator = \"sppm\"\nalpha = 1.5\n", p + ":9: run[1].alpha: must be in (0, 1]"},
      {kHead + "[[run]]\nintegrator = \"photon\"\nradius = -0.1\n", p + ":9: run[1].radius: must be in (0"},
      {kHead + "[[run]]\nintegrator = \"photon\"\nkernel = \"gauss\"\n", p + ":9: run[1].kernel: unknown kernel 'gauss'"},
      {kHead + "[[run]]\nintegrator = \"metropolis\"\n", p + ":8: run[1].integrator: unknown integrator 'metropolis'"},
      {kHead + "[[run]]\nspp = 4\n", p + ":7: run[1]: needs an integrator"},
      {kHead + "[[run]]\nintegrator = \"path\"\ntime = nan\n", p + ":9: run[1].time: must be in (0"},
      {kHead + "[[run]]\nintegrator = \"path\"\nseeds = [1, 1]\n", p + ":9: run[1].seeds: seed 1 is listed twice"},
      {kHead + "[[run]]\nintegrator = \"path\"\n[[run]]\nintegrator = \"path\"\nlabel = \"path 1\"\n", "run[2].label: 'path 1' is used"},
      {kHead + "[[run]]\nintegrator = \"path\"\nspp = 4\nspp = 5\n", p + ":10: "},  // TOML: duplicate key
      {"name = \"t\"\nscene = \"missing.gltf\"\n", p + ":2: scene: no such file"},
      {"name = \"../up\"\n", p + ":1: name: must be a folder name"},
      {"name = \"t\"\nscene = \"scene.gltf\"\nwidht = 3\n", p + ":3: widht: unknown key"},
      {"name = \"t\"\nscene = \"scene.gltf\"\n[[run]]\nintegrator = \"path\"\n", "reference: missing"},
      {kHead, "run: missing"},
      {"name = \"t\"\nscene = \"scene.gltf\"\n[reference]\nfile = \"nope.exr\"\n", p + ":4: reference.file: no such file"},
      {kHead + "inset = [1, 2]\n", p + ":7: reference.inset: unknown key"},  // inset after [reference] belongs to it
      {"name = \"t\"\nscene = \"scene.gltf\"\nwidth = 8\nheight = 8\ninset = [4, 4, 8, 8]\n" + kHead.substr(kHead.find("[reference]")) +
           "[[run]]\nintegrator = \"path\"\n",
       "inset: region lies outside the image"},
      {"name = \"t\"\n[unclosed\n", p + ":2: "},
      {"tonemap = \"filmic\"\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: tonemap: unknown tone curve 'filmic' (clamp, aces)"},
      {"exposure = \"+1\"\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: exposure: must be a number"},
      {"baseline = \"PT\"\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: baseline: no run is labelled 'PT'"},
      {"target_relmse = 0\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: target_relmse: must be in (0"},
      {"env = -1\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: env: must be in [0"},
      {"env = \"1,2\"\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: env: expected R,G,B"},
      {"env = [1, \"x\", 1]\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: env: must be a number"},
      {"units = \"lumens\"\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: units: must be \"radiometric\" or \"photometric\""},
      {"env_rotate = 30\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":1: env_rotate: needs env"},
      {"env = 1\nenv_scale = -2\n" + kHead + "[[run]]\nintegrator = \"path\"\n", p + ":2: env_scale: must be in [0"},
  };
  for (auto& c : cases) {
    std::string e = f.error(c.text);
    INFO(c.text << "\n=> " << e);
    CHECK_THAT(e, Contains(c.mentions));
    CHECK(e.find('\n') == std::string::npos);
  }
}

// Found by fuzzing (scripts/fuzz.sh experiment): a config path without a folder made
// std::filesystem::absolute("") throw instead of resolving against the working directory.
TEST_CASE("experiment config: a config named without a folder resolves against the working directory") {
  ConfigFixture f;
  auto cwd = fs::current_path();
  fs::current_path(f.dir);
  ExperimentConfig c;
  CHECK_NOTHROW(c = parseExperiment(kHead + "[[run]]\nintegrator = \"path\"\n", "exp.toml"));
  CHECK(c.scene == fs::path(f.dir + "/scene.gltf").lexically_normal().string());
  std::string nul = "name = \"t\"\nscene = \"a\\u0000b\"\n";
  CHECK_THROWS_WITH(parseExperiment(nul, "exp.toml"), Contains("exp.toml:2: scene: not a usable file name"));
  fs::current_path(cwd);
}

TEST_CASE("experiment config: the fingerprint changes with what is rendered - not with threads") {
  ConfigFixture f;
  auto base = f.parse(kHead + "[[run]]\nintegrator = \"sppm\"\npasses = 8\n");
  auto alpha = f.parse(kHead + "[[run]]\nintegrator = \"sppm\"\npasses = 8\nalpha = 0.5\n");
  auto threads = f.parse("threads = 1\n" + kHead + "[[run]]\nintegrator = \"sppm\"\npasses = 8\n");
  CHECK(settingsFingerprint(base.runs[0].settings) != settingsFingerprint(alpha.runs[0].settings));
  CHECK(settingsFingerprint(base.runs[0].settings) == settingsFingerprint(threads.runs[0].settings));
  // The resolved config (results/<name>/experiment.toml) is itself a config with the same meaning.
  std::string resolved = resolvedConfigToml(alpha, {{"git_revision", "abc"}});
  CHECK_THAT(resolved, Contains("alpha = 0.5"));
  CHECK_THAT(resolved, Contains("git_revision = 'abc'"));
  auto again = f.parse(resolved);
  CHECK(settingsFingerprint(again.runs[0].settings) == settingsFingerprint(alpha.runs[0].settings));
  CHECK(settingsFingerprint(again.reference.settings) == settingsFingerprint(alpha.reference.settings));
  CHECK(again.runs[0].seeds == alpha.runs[0].seeds);
}

TEST_CASE("experiment config: env and units - for the reference and every run, in the fingerprint and the resolved config") {
  ConfigFixture f;
  auto none = f.parse(kHead + "[[run]]\nintegrator = \"path\"\n");
  auto grey = f.parse("env = 0.5\n" + kHead + "[[run]]\nintegrator = \"path\"\n");
  auto rgb = f.parse("env = [0.2, 0.4, 0.6]\n" + kHead + "[[run]]\nintegrator = \"path\"\n");
  auto map = f.parse("env = \"skies/noon.exr\"\nenv_rotate = 90\nenv_scale = 2\n" + kHead + "[[run]]\nintegrator = \"path\"\n");
  CHECK_FALSE(none.runs[0].settings.image.environment.enabled);
  CHECK(grey.runs[0].settings.image.environment.radiance == Spectrum(0.5f));
  CHECK(grey.reference.settings.image.environment.radiance == Spectrum(0.5f));
  CHECK(rgb.runs[0].settings.image.environment.radiance == Spectrum(0.2f, 0.4f, 0.6f));
  const EnvironmentSpec& m = map.runs[0].settings.image.environment;
  CHECK(m.map == (fs::path(f.dir) / "skies/noon.exr").lexically_normal().string());  // relative to the config
  CHECK(m.rotation == 90.0f);
  CHECK(m.scale == 2.0f);
  CHECK(settingsFingerprint(none.runs[0].settings) != settingsFingerprint(grey.runs[0].settings));
  CHECK(settingsFingerprint(grey.runs[0].settings) != settingsFingerprint(rgb.runs[0].settings));
  // units: as --units, for the reference and every run.
  auto units = f.parse("units = \"photometric\"\n" + kHead + "[[run]]\nintegrator = \"path\"\n");
  CHECK(units.runs[0].settings.image.units == "photometric");
  CHECK(units.reference.settings.image.units == "photometric");
  CHECK(settingsFingerprint(units.runs[0].settings) != settingsFingerprint(none.runs[0].settings));
  CHECK(settingsFingerprint(f.parse(resolvedConfigToml(units, {})).runs[0].settings) == settingsFingerprint(units.runs[0].settings));
  for (auto* c : {&rgb, &map}) {
    auto again = f.parse(resolvedConfigToml(*c, {}));
    CHECK(settingsFingerprint(again.runs[0].settings) == settingsFingerprint(c->runs[0].settings));
  }
}

TEST_CASE("experiment config: the shipped experiments parse") {
  int count = 0;
  for (auto& e : fs::directory_iterator(std::string(PHOTONLAB_SOURCE_DIR) + "/experiments")) {
    if (e.path().extension() != ".toml") continue;
    INFO(e.path());
    auto c = loadExperiment(e.path().string());
    CHECK(c.name == e.path().stem().string());
    CHECK_FALSE(c.runs.empty());
    ++count;
  }
  CHECK(count >= 5);
}
