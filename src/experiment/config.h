// An experiment: one scene, one reference, several runs (integrator + parameters + budget), each
// over one or more seeds. Read from TOML (experiments/*.toml); experimentKeys() below lists the
// keys, and the documentation's reference page is generated from it. Everything is validated here, before anything renders: an unknown key, a wrong type or an
// out-of-range value is an Error "FILE:LINE: KEY: what".
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "integrators/registry.h"
#include "image/tonemap.h"
#include "render/render_options.h"

namespace pl {

// One way of rendering the experiment's scene: everything `photonlab render` takes, minus the
// outputs. Budgets: `spp` (or `passes`) and/or `time`; whichever comes first ends the run.
struct RunSettings {
  std::string integrator = "path";
  RenderOptions image;  // width/height/seed/threads come from the experiment; time, spectral
  ParamSet params = integratorEntry("path").defaults();  // the integrator's declared parameters

  // `name`'s defaults; throws Error for an unknown name.
  static RunSettings of(const std::string& name);
  const IntegratorEntry& entry() const { return integratorEntry(integrator); }
  // What the integrator renders with: `image` with spp from the parameters when it declares it.
  RenderOptions renderOptions() const;
  // The render's budget unit: "spp" or "passes".
  std::string budgetUnit() const;
  // Run keys every integrator takes (beside its own parameters).
  static const std::vector<std::string>& commonKeys();
};

struct RunConfig {
  std::string label;
  std::vector<uint64_t> seeds;
  RunSettings settings;
  int line = 0;  // where the run starts in the config, for messages
};

// Seeds are signed 64-bit integers. Runs take seeds ≥ 0; the reference, unless its config
// names a seed, draws from seed −1, a stream no run can reach: a reference sharing random numbers
// with a run would make that run's error look smaller than it is (docs: how-to/reference.md).
constexpr uint64_t kReferenceSeed = ~uint64_t(0);  // −1 as a signed seed
inline std::string seedString(uint64_t seed) { return std::to_string(int64_t(seed)); }

struct ReferenceConfig {
  std::string file;      // an existing image (absolute path), or empty: render `settings`
  RunSettings settings;  // seed: kReferenceSeed, or the [reference] table's seed
};

struct ExperimentConfig {
  std::string path;         // the config file
  std::string name;         // results/<name>/
  std::string description;
  std::string scene;        // absolute (resolved against the config's folder)
  int width = 0, height = 0;  // 0 height: from the camera's aspect ratio once the scene is loaded
  int threads = 0;
  std::optional<std::array<int, 4>> inset;  // x, y, w, h in pixels: the zoomed region of the comparison figure
  Display display;           // exposure (EV) and tone curve of the PNGs and figures; EXR stays linear
  std::string baseline;      // the run the report's speed-ups are relative to (a label; default: the first run)
  double targetRelmse = 0;   // the report's "time to reach" target; 0: the baseline's final relMSE
  ReferenceConfig reference;
  std::vector<RunConfig> runs;
};

// The reference's settings, then every run's.
std::vector<RunSettings*> allSettings(ExperimentConfig& config);

// A key of the experiment TOML: the table it belongs in ("" for the top level, "reference",
// "run"), its TOML type, and one line of meaning. The parser's "unknown key" message and the
// documentation (`photonlab reference experiment`) are both made from this list.
struct ConfigKey {
  std::string table, key, type, doc;
};
const std::vector<ConfigKey>& experimentKeys();

// Throws Error naming `path`, the line and the key.
ExperimentConfig parseExperiment(std::string_view text, const std::string& path);
ExperimentConfig loadExperiment(const std::string& path);  // reads the file, then parseExperiment

// The config with every default filled in (and the resolution resolved), as TOML; `extra` lines
// (provenance) are appended as a [provenance] table of strings.
std::string resolvedConfigToml(const ExperimentConfig& config,
                               const std::vector<std::pair<std::string, std::string>>& provenance);

// The parameters that define a run's result, as "key=value" lines: the reference cache key hashes
// this, and resumed experiments compare it.
std::string settingsFingerprint(const RunSettings& s);

}  // namespace pl
