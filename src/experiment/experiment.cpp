#include "experiment/experiment.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>
#include <toml++/toml.h>

#include "core/interrupt.h"
#include "io/image_io.h"
#include "io/metrics.h"
#include "scene/gltf_loader.h"

namespace pl {
namespace fs = std::filesystem;

extern const char* const kGitRevision;  // generated at build time (scripts/git_revision.cmake)

// ---------------------------------------------------------------------------------------------
// One run, whatever the integrator family.

ImageRGB renderRun(const Scene& scene, const RunSettings& s, const RunCheckpointFn& checkpoint, CheckpointInfo* final,
                   std::vector<std::string>* warnings, uint64_t* nonFiniteSamples, std::vector<NamedImage>* extraImages,
                   std::vector<std::string>* notes) {
  RenderOptions o = s.renderOptions();
  auto integrator = makeIntegrator(s.integrator, s.params, o);
  o.checkpoint = checkpoint;
  RenderInfo info;
  ImageRGB image = integrator->render(scene, o, &info);
  if (warnings)
    for (auto& w : integrator->warnings()) warnings->push_back(w);
  if (extraImages) *extraImages = integrator->extraImages();
  if (notes) *notes = integrator->notes();
  info.last = true;
  if (final) *final = info;
  if (nonFiniteSamples) *nonFiniteSamples = info.nonFiniteSamples;
  return image;
}

std::map<std::string, std::string> runMetadata(const RunSettings& s, const CheckpointInfo& info, const std::string& scenePath) {
  std::map<std::string, std::string> m = {
      {"integrator", s.integrator},         {"seed", seedString(s.image.seed)}, {"git_revision", kGitRevision},
      {"seconds", formatNumber(info.seconds)},    {"scene", scenePath},
      {"width", std::to_string(s.image.width)}, {"height", std::to_string(s.image.height)}};
  // Every declared parameter (unset ones as 0: e.g. radius 0, k nearest instead).
  for (const ParamSpec& p : s.params.specs()) m[p.metaKey()] = s.params.format(p);
  if (s.image.camera >= 0) m["camera"] = std::to_string(s.image.camera);
  if (s.image.view.given()) m["view"] = s.image.view.describe();
  if (s.image.environment.enabled) m["environment"] = s.image.environment.describe();
  if (!s.image.units.empty()) m["units"] = s.image.units;
  // Then what was done: the samples or passes reached (over the budget parameter, which only
  // said how many were asked for), photon paths traced, the gather radius reached.
  const std::string unit = s.budgetUnit();
  const int done = unit == "passes" ? info.passes : info.spp;
  m[unit] = std::to_string(done);
  if (info.meanWork != done) m["mean_" + unit] = formatNumber(info.meanWork);
  if (info.photons > 0 && !s.params.has("photons")) m["photons"] = std::to_string(info.photons);
  if (info.meanRadius > 0) m[m.count("radius") ? "mean_radius" : "radius"] = formatNumber(info.meanRadius);
  if (info.visibleFraction >= 0) m["visible_photons"] = formatNumber(info.visibleFraction);
  if (info.visiblePaths >= 0) m["visible_paths"] = formatNumber(info.visiblePaths);
  if (m.count("aov") && m["aov"] == "radiance") m.erase("aov");
  if (s.image.nanAov) m["aov"] = "nan";
  if (s.image.spectral) m["spectral"] = "1";
  if (s.image.timeLimit > 0) m["time_budget"] = formatNumber(s.image.timeLimit);
  if (info.timeUp) m["time_up"] = "1";
  if (info.interrupted) m["partial"] = "1";
  return m;
}

const std::vector<MetadataKey>& metadataKeys() {
  static const std::vector<MetadataKey> keys = {
      {"integrator", "The integrator's name."},
      {"seed", "The random seed (-1: an experiment's reference stream)."},
      {"git_revision", "The revision photonlab was built from (`-dirty` with uncommitted changes)."},
      {"seconds", "Wall time spent, scene set-up and photon maps included; a merge adds its slices' times."},
      {"scene", "The scene file as given."},
      {"width", "Image width in pixels."},
      {"height", "Image height in pixels."},
      {"camera", "`--camera`: which of the file's cameras rendered (absent: the first, or the automatic view)."},
      {"view", "The view given instead of the file's camera, as the flags that make it (`--look-from`/`--look-at`/`--up`, `--orbit`, `--fov`)."},
      {"environment", "The sky, when there is one: its radiance or map, rotation and scale."},
      {"units", "`--units` (or the experiment's `units`) when given."},
      {"spp", "Samples every pixel received (camera-side and bidirectional integrators: iterations)."},
      {"passes", "Passes completed (integrators counted in passes)."},
      {"mean_spp", "The mean samples per pixel, when a time budget cut the last sample pass short."},
      {"mean_passes", "The same in passes."},
      {"photons", "Photon paths traced (when not a declared parameter)."},
      {"radius", "The gather radius used or reached (m), when the integrator does not declare `radius`."},
      {"mean_radius", "The mean gather radius reached (m), beside a declared `radius`."},
      {"visible_photons", "ppm, sppm, pppm: of the photons stored that a gather could use, the fraction some visible point's gather found (Hachisuka & Jensen's visibility); a merge weights its slices' by their photon paths."},
      {"visible_paths", "ppm, sppm, pppm with photon_sampling adaptive: the fraction of the uniformly drawn photon paths that were visible (V̂c, the chain's normalisation; Hachisuka & Jensen 2011); a merge weights its slices' by their photon paths."},
      {"aov", "A debug image instead of radiance: `nan`, `photons`, `radius`, ..."},
      {"spectral", "1: rendered spectrally."},
      {"time_budget", "`--time` in seconds, when given."},
      {"time_up", "1: the time budget ended the render."},
      {"partial", "1: the render was interrupted (the image is `OUT.partial.exr`)."},
      {"exposure", "PNG only: the exposure in EV."},
      {"exposure_rule", "PNG only, with `--exposure auto`: how the exposure was metered from the image."},
      {"tonemap", "PNG only: the tone curve."},
      {"range_begin", "A slice (`--sample-range`, `--pass-range`): its first sample or pass."},
      {"range_end", "A slice: one past its last sample or pass."},
      {"range_step", "A slice: every k-th sample or pass from `range_begin`."},
      {"merged_slices", "`photonlab merge`: how many original slices the image adds up."},
      {"label", "An experiment's run label."},
      {"experiment", "The experiment's name."},
      {"cache_key", "A cached reference: the hash of its settings, scene bytes and cache version."},
      {"reference_file", "An experiment whose reference is a given file: that file."},
      {"reference_integrator", "An experiment's run: the reference's integrator (likewise `reference_seed`, `reference_seconds`, `reference_spp`, `reference_passes`, `reference_photons`, `reference_git_revision`)."},
  };
  return keys;
}

const std::vector<std::string>& metricsColumns() {
  static const std::vector<std::string> columns = {
      "run",    "label",  "integrator", "seed", "checkpoint", "seconds",    "spp",         "passes",
      "photons", "rmse",  "relmse",     "mae",  "mean_ratio", "mean_radius", "final",      "image"};
  return columns;
}

// ---------------------------------------------------------------------------------------------
// The experiment.

namespace {

uint64_t fnv1a(const std::string& bytes, uint64_t h = 0xcbf29ce484222325ULL) {
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw Error(p.string() + ": cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)v);
  return buf;
}

// The scene's bytes: the glTF file and, for .gltf, every external buffer and image it names
// (a changed .bin must invalidate a cached reference too).
std::string sceneBytes(const std::string& scenePath) {
  std::string bytes = readFile(scenePath);
  if (fs::path(scenePath).extension() != ".gltf") return bytes;
  nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return bytes;
  std::string all = bytes;
  for (const char* list : {"buffers", "images"}) {
    if (!j.contains(list) || !j[list].is_array()) continue;
    for (auto& e : j[list]) {
      if (!e.is_object() || !e.contains("uri") || !e["uri"].is_string()) continue;
      std::string uri = e["uri"];
      if (uri.rfind("data:", 0) == 0) continue;
      fs::path p = fs::path(scenePath).parent_path() / uri;
      if (fs::is_regular_file(p)) all += readFile(p);
    }
  }
  return all;
}

// Bump when a change to the renderers makes cached references wrong.
constexpr int kReferenceCacheVersion = 2;  // 2: directional lights' photons fixed

std::string slug(const std::string& label) {
  std::string s;
  for (char c : label) {
    unsigned char u = static_cast<unsigned char>(c);
    if (std::isalnum(u)) s += char(std::tolower(u));
    else if (!s.empty() && s.back() != '-') s += '-';
    if (s.size() >= 40) break;
  }
  while (!s.empty() && s.back() == '-') s.pop_back();
  return s.empty() ? "run" : s;
}

std::string csvField(const std::string& v) {
  if (v.find_first_of(",\"\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::vector<std::string> csvSplit(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') out.back() += '"', ++i;
      else if (c == '"') quoted = false;
      else out.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

void writeFileAtomic(const fs::path& path, const std::string& text) {
  fs::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw Error(path.string() + ": cannot write");
    }
  }
  fs::rename(tmp, path);
}

// The processor's model name (/proc/cpuinfo), or "unknown".
std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) != 0) continue;
    auto colon = line.find(':');
    if (colon == std::string::npos) break;
    std::string model = line.substr(colon + 1);
    while (!model.empty() && model.front() == ' ') model.erase(model.begin());
    return model;
  }
  return "unknown";
}

// The config hash a previous `photonlab run` recorded in DIR/experiment.toml, or "".
std::string recordedConfigHash(const fs::path& file) {
  try {
    return toml::parse_file(file.string())["provenance"]["config_hash"].value_or(std::string());
  } catch (const toml::parse_error&) {
    return "";
  }
}

struct Row {
  int run;
  uint64_t seed;
  bool final;
  std::string line;
};

class Experiment {
 public:
  Experiment(ExperimentConfig config, const ExperimentOptions& o) : c_(std::move(config)), o_(o) {}

  int run() {
    if (o_.listRuns) {  // "RUN SEED" per line, 1-based runs, in the order `run` renders them
      for (size_t i = 0; i < c_.runs.size(); ++i)
        for (uint64_t seed : c_.runs[i].seeds) std::printf("%zu %llu\n", i + 1, (unsigned long long)seed);
      return 0;
    }
    if (o_.onlyRun) {
      const auto& seeds = o_.onlyRun <= int(c_.runs.size()) ? c_.runs[o_.onlyRun - 1].seeds : std::vector<uint64_t>{};
      if (std::find(seeds.begin(), seeds.end(), o_.onlySeed) == seeds.end())
        throw Error("--only " + std::to_string(o_.onlyRun) + ":" + std::to_string(o_.onlySeed) + ": " + c_.path +
                    " has no such run and seed (--list-runs lists them)");
    }
    std::vector<std::string> warnings;
    GltfLoadOptions load;
    load.environment = c_.runs.front().settings.image.environment;  // every run's and the reference's
    load.readImage = readEnvironmentMap;
    load.units = c_.runs.front().settings.image.units;
    scene_ = loadGltf(c_.scene, &warnings, load);
    for (auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    setInterruptCooperative(true);  // from here on an interrupt keeps what is finished (docs: how-to/checkpoint-resume.md)
    resolveSizes();
    chooseFolder();
    renderReference();
    if (o_.referenceOnly) return 0;
    if (o_.onlyRun) return renderOnly();
    return renderRuns();
  }

 private:
  void resolveSizes() {
    RenderOptions size;
    size.width = c_.width;
    size.height = c_.height;
    resolveResolution(scene_->camera(), size);
    c_.width = size.width;
    c_.height = size.height;
    if (c_.inset && ((*c_.inset)[0] + (*c_.inset)[2] > c_.width || (*c_.inset)[1] + (*c_.inset)[3] > c_.height))
      throw Error(c_.path + ": inset: region lies outside the " + std::to_string(c_.width) + "x" +
                  std::to_string(c_.height) + " image");
    if (o_.threads >= 0) c_.threads = o_.threads;
    for (RunSettings* s : allSettings(c_)) {
      s->image.width = c_.width;
      s->image.height = c_.height;
      s->image.threads = c_.threads;
      // The progressive methods' default radius depends on the scene: fill it in, so that the
      // resolved config and the images' metadata say what was used.
      if (s->entry().resolve) s->entry().resolve(*scene_, c_.width, c_.height, s->params);
    }
    // The fingerprint of what would be rendered; threads do not change results (deterministic).
    std::string key = c_.scene + "\n" + c_.reference.file + "\n" + settingsFingerprint(c_.reference.settings);
    for (auto& r : c_.runs) {
      key += r.label + "\n" + settingsFingerprint(r.settings);
      for (auto s : r.seeds) key += std::to_string(s) + ",";
    }
    configHash_ = hex(fnv1a(key));
  }

  // results/<name>/ unless it holds something else: see docs/pages/how-to/checkpoint-resume.md.
  void chooseFolder() {
    const bool explicitOut = !o_.out.empty();
    fs::path base = explicitOut ? fs::path(o_.out) : fs::path("results") / c_.name;
    for (int attempt = 1;; ++attempt) {
      fs::path dir = attempt == 1 ? base : fs::path(base.string() + "-" + std::to_string(attempt));
      std::string state = folderState(dir);
      if (state == "empty") {
        out_ = dir;
        break;
      }
      if (o_.force) {
        std::fprintf(stderr, "run: --force: removing %s\n", dir.string().c_str());
        fs::remove_all(dir);
        out_ = dir;
        break;
      }
      if (state == "resumable") {
        out_ = dir;
        resuming_ = true;
        break;
      }
      if (explicitOut) {
        throw Error(dir.string() + ": " +
                    (state == "finished" ? "holds this experiment, finished; --force renders it again"
                                         : "holds other files or another experiment; choose another --out or --force"));
      }
    }
    fs::create_directories(out_ / "runs");
    std::vector<std::pair<std::string, std::string>> provenance = {
        {"config_file", fs::absolute(c_.path).lexically_normal().string()},
        {"config_hash", configHash_},
        {"git_revision", kGitRevision},
        {"cores", std::to_string(std::thread::hardware_concurrency())},
        {"cpu", cpuModel()},
        {"photonlab_threads", std::to_string(c_.threads)},
    };
    if (!resuming_) writeFileAtomic(out_ / "experiment.toml", resolvedConfigToml(c_, provenance));
    if (!o_.quiet)
      std::fprintf(stderr, "run: %s -> %s%s\n", c_.name.c_str(), out_.string().c_str(), resuming_ ? " (resuming)" : "");
  }

  // "empty", "resumable" (same experiment, unfinished), "finished" or "other".
  std::string folderState(const fs::path& dir) {
    if (!fs::exists(dir)) return "empty";
    if (!fs::is_directory(dir)) return "other";
    if (fs::is_empty(dir)) return "empty";
    if (!fs::is_regular_file(dir / "experiment.toml")) return "other";
    if (recordedConfigHash(dir / "experiment.toml") != configHash_) return "other";
    // Finished means metrics.csv holds every run; rows still in the runs' own files (from
    // --only processes) are to be collected, which is resuming.
    loadRows(dir, false);
    size_t finished = 0, total = 0;
    for (size_t i = 0; i < c_.runs.size(); ++i)
      for (auto seed : c_.runs[i].seeds) {
        ++total;
        finished += isFinished(dir, int(i + 1), seed);
      }
    return finished == total ? "finished" : "resumable";
  }

  // metrics.csv's rows, and (with `fragments`) those of the runs rendered by --only processes,
  // each row once, ordered as `run` writes them: by run, seed in the config's order, checkpoint.
  void loadRows(const fs::path& dir, bool fragments = true) {
    rows_.clear();
    std::vector<fs::path> files = {dir / "metrics.csv"};
    if (fragments && fs::is_directory(dir / "runs"))
      for (auto& run : fs::directory_iterator(dir / "runs"))
        if (run.is_directory())
          for (auto& seed : fs::directory_iterator(run.path()))
            if (fs::is_regular_file(seed.path() / "metrics-rows.csv")) files.push_back(seed.path() / "metrics-rows.csv");
    std::set<std::tuple<int, uint64_t, int>> seen;
    for (const fs::path& file : files) {
      std::ifstream in(file);
      std::string line;
      if (!std::getline(in, line)) continue;  // the header
      while (std::getline(in, line)) {
        auto f = csvSplit(line);
        if (f.size() != metricsColumns().size()) continue;  // a torn line
        try {
          Row row{std::stoi(f[0]), std::stoull(f[3]), f[14] == "1", line};
          if (seen.insert({row.run, row.seed, std::stoi(f[4])}).second) rows_.push_back(row);
        } catch (const std::exception&) {
        }
      }
    }
    auto order = [&](const Row& r) {
      const auto& seeds = r.run >= 1 && r.run <= int(c_.runs.size()) ? c_.runs[r.run - 1].seeds : std::vector<uint64_t>{};
      size_t seedIndex = std::find(seeds.begin(), seeds.end(), r.seed) - seeds.begin();
      return std::make_tuple(r.run, seedIndex, std::stoi(csvSplit(r.line)[4]));
    };
    std::stable_sort(rows_.begin(), rows_.end(), [&](const Row& a, const Row& b) { return order(a) < order(b); });
  }

  fs::path runFolder(int run, uint64_t seed) const {
    char prefix[16];
    std::snprintf(prefix, sizeof prefix, "%02d-", run);
    return fs::path("runs") / (prefix + slug(c_.runs[run - 1].label)) / ("seed-" + std::to_string(seed));
  }

  bool isFinished(const fs::path& dir, int run, uint64_t seed) const {
    for (auto& r : rows_)
      if (r.run == run && r.seed == seed && r.final) return fs::is_regular_file(dir / runFolder(run, seed) / "final.exr");
    return false;
  }

  void writeMetrics() {
    std::string text;
    for (size_t i = 0; i < metricsColumns().size(); ++i) text += (i ? "," : "") + metricsColumns()[i];
    text += "\n";
    for (auto& r : rows_) text += r.line + "\n";
    writeFileAtomic(metricsFile_.empty() ? out_ / "metrics.csv" : metricsFile_, text);
  }

  // --only RUN:SEED: that run alone, its rows in its own folder. Nothing to do when a previous
  // attempt finished it (a task run twice by a cluster that lost its worker).
  int renderOnly() {
    const int run = o_.onlyRun;
    const uint64_t seed = o_.onlySeed;
    loadRows(out_);
    if (isFinished(out_, run, seed)) {
      if (!o_.quiet) std::fprintf(stderr, "run: %d:%llu is finished\n", run, (unsigned long long)seed);
      return 0;
    }
    rows_.clear();
    metricsFile_ = out_ / runFolder(run, seed) / "metrics-rows.csv";
    return renderOne(run, seed) ? 0 : 130;
  }

  void renderReference() {
    if (!c_.reference.file.empty()) {
      reference_ = readImage(c_.reference.file);
      if (reference_.width != c_.width || reference_.height != c_.height)
        throw Error(c_.reference.file + ": reference is " + std::to_string(reference_.width) + "x" +
                    std::to_string(reference_.height) + ", the experiment renders " + std::to_string(c_.width) + "x" +
                    std::to_string(c_.height));
      if (!o_.onlyRun) {  // --only processes run side by side: the reference files are the others' to write
        writeImage((out_ / "reference.exr").string(), reference_, {{"reference_file", c_.reference.file}});
        writeImage((out_ / "reference.png").string(), reference_, {}, c_.display);
      }
      referenceSummary_ = {{"reference_file", c_.reference.file}};
      return;
    }
    const RunSettings& s = c_.reference.settings;
    const std::string key = "photonlab reference cache v" + std::to_string(kReferenceCacheVersion) + "\n" +
                            settingsFingerprint(s) + "\n" + sceneBytes(c_.scene) +
                            (s.image.environment.map.empty() ? "" : "\n" + readFile(s.image.environment.map));
    fs::path cacheDir = o_.cache.empty() ? out_.parent_path() / ".reference-cache" : fs::path(o_.cache);
    if (cacheDir.empty()) cacheDir = ".reference-cache";
    fs::path cached = cacheDir / (fs::path(c_.scene).stem().string() + "-" + s.integrator + "-" + hex(fnv1a(key)) + ".exr");
    if (fs::is_regular_file(cached)) {
      reference_ = readImage(cached.string());
      if (!o_.quiet) std::fprintf(stderr, "run: reference from cache %s\n", cached.string().c_str());
    } else {
      if (!o_.quiet) std::fprintf(stderr, "run: rendering the reference (%s) into %s\n", s.integrator.c_str(), cached.string().c_str());
      fs::create_directories(cacheDir);
      CheckpointInfo info;
      std::vector<std::string> warnings;
      RunSettings rs = s;
      rs.image.progress = !o_.quiet;
      reference_ = renderRun(*scene_, rs, nullptr, &info, &warnings);
      for (auto& w : warnings) std::fprintf(stderr, "warning: reference: %s\n", w.c_str());
      if (info.interrupted) {
        std::fprintf(stderr, "run: interrupted while rendering the reference; nothing cached\n");
        throw Interrupted();
      }
      auto meta = runMetadata(s, info, c_.scene);
      meta["cache_key"] = hex(fnv1a(key));
      writeImage(cached.string(), reference_, meta);
    }
    // --only processes run side by side: the reference files are the others' to write.
    if (!o_.onlyRun) {
      std::error_code ec;
      fs::remove(out_ / "reference.exr", ec);
      fs::copy_file(cached, out_ / "reference.exr", fs::copy_options::overwrite_existing);
      writeImage((out_ / "reference.png").string(), reference_, {}, c_.display);
    }
    // What every run's images say about the reference they were measured against.
    auto meta = readImageMetadata(cached.string());
    for (const char* k : {"integrator", "seed", "seconds", "spp", "passes", "photons", "git_revision"})
      if (meta.count(k)) referenceSummary_[std::string("reference_") + k] = meta[k];
  }

  int renderRuns() {
    if (resuming_) loadRows(out_);
    // Rows of unfinished runs are dropped; those runs start again.
    std::vector<Row> kept;
    for (auto& r : rows_)
      if (r.run >= 1 && r.run <= int(c_.runs.size()) && isFinished(out_, r.run, r.seed)) kept.push_back(r);
    rows_ = kept;
    writeMetrics();

    size_t total = 0, done = 0;
    for (auto& r : c_.runs) total += r.seeds.size();
    for (size_t i = 0; i < c_.runs.size(); ++i) {
      for (uint64_t seed : c_.runs[i].seeds) {
        const int run = int(i + 1);
        if (isFinished(out_, run, seed)) {
          ++done;
          continue;
        }
        if (!renderOne(run, seed)) {
          std::fprintf(stderr,
                       "run: interrupted: %zu of %zu runs finished and kept in %s; the same command resumes it\n",
                       done, total, out_.string().c_str());
          return 130;
        }
        ++done;
      }
    }
    summary();
    std::printf("%s\n", out_.string().c_str());  // the only line on stdout: for scripts
    return 0;
  }

  // Returns false when interrupted.
  bool renderOne(int run, uint64_t seed) {
    const RunConfig& rc = c_.runs[run - 1];
    RunSettings s = rc.settings;
    s.image.seed = seed;
    const fs::path folder = runFolder(run, seed);
    fs::remove_all(out_ / folder);
    fs::create_directories(out_ / folder);
    if (!o_.quiet) std::fprintf(stderr, "run %d/%zu '%s' (%s), seed %llu\n", run, c_.runs.size(), rc.label.c_str(),
                                s.integrator.c_str(), (unsigned long long)seed);
    int index = 0;
    bool interrupted = false;
    auto checkpoint = [&](const ImageRGB& image, const CheckpointInfo& info) {
      ++index;
      auto meta = runMetadata(s, info, c_.scene);
      meta["label"] = rc.label;
      meta["experiment"] = c_.name;
      for (auto& [k, v] : referenceSummary_) meta[k] = v;
      // Checkpoints are spp-NNNN.exr (pass-NNNN.exr); the last one is final.exr, or partial.exr
      // when interrupted, with a PNG beside it. Each image is written once.
      const bool final = info.last && !info.interrupted;
      interrupted = interrupted || info.interrupted;
      char name[48];
      if (info.interrupted) std::snprintf(name, sizeof name, "partial.exr");
      else if (final) std::snprintf(name, sizeof name, "final.exr");
      else if (s.budgetUnit() == "passes") std::snprintf(name, sizeof name, "pass-%04d.exr", info.passes);
      else std::snprintf(name, sizeof name, "spp-%04d.exr", info.spp);
      const fs::path image_rel = folder / name;
      writeImage((out_ / image_rel).string(), image, meta);
      if (info.last) writeImage((out_ / fs::path(image_rel).replace_extension(".png")).string(), image, meta, c_.display);
      ErrorMetrics m = compareImages(image, reference_);
      std::vector<std::string> f = {std::to_string(run),
                                    rc.label,
                                    s.integrator,
                                    std::to_string(seed),
                                    std::to_string(index),
                                    formatNumber(info.seconds),
                                    std::to_string(info.spp),
                                    std::to_string(info.passes),
                                    std::to_string(info.photons),
                                    formatNumber(m.rmse),
                                    formatNumber(m.relmse),
                                    formatNumber(m.mae),
                                    formatNumber(m.meanRatio),
                                    formatNumber(info.meanRadius),
                                    final ? "1" : "0",
                                    image_rel.string()};
      std::string line;
      for (size_t i = 0; i < f.size(); ++i) line += (i ? "," : "") + csvField(f[i]);
      rows_.push_back({run, seed, final, line});
      writeMetrics();
      if (!o_.quiet)
        std::fprintf(stderr, "  %8.2f s  %s %-5d relMSE %.4g%s\n", info.seconds, s.budgetUnit().c_str(),
                     s.budgetUnit() == "passes" ? info.passes : info.spp, m.relmse, final ? "  (final)" : "");
    };
    std::vector<std::string> warnings;
    uint64_t nonFinite = 0;
    renderRun(*scene_, s, checkpoint, nullptr, &warnings, &nonFinite);
    for (auto& w : warnings) std::fprintf(stderr, "warning: %s: %s\n", rc.label.c_str(), w.c_str());
    if (nonFinite) std::fprintf(stderr, "warning: %s: %llu non-finite samples discarded\n", rc.label.c_str(), (unsigned long long)nonFinite);
    return !interrupted;
  }

  void summary() {
    if (o_.quiet) return;
    std::fprintf(stderr, "\n%-32s %-10s %6s %9s %12s\n", "run", "integrator", "seed", "seconds", "relMSE");
    for (auto& r : rows_) {
      if (!r.final) continue;
      auto f = csvSplit(r.line);
      std::fprintf(stderr, "%-32.32s %-10s %6s %9.2f %12.4g\n", f[1].c_str(), f[2].c_str(), f[3].c_str(), std::stod(f[5]),
                   std::stod(f[10]));
    }
    std::fprintf(stderr, "\nresults in %s (metrics.csv, experiment.toml, runs/); report: scripts/report.py %s\n",
                 out_.string().c_str(), out_.string().c_str());
  }

  ExperimentConfig c_;
  ExperimentOptions o_;
  std::unique_ptr<Scene> scene_;
  std::string configHash_;
  fs::path out_;
  bool resuming_ = false;
  fs::path metricsFile_;  // empty: out_/metrics.csv
  ImageRGB reference_;
  std::map<std::string, std::string> referenceSummary_;  // reference_integrator, _seed, _seconds, ...
  std::vector<Row> rows_;
};

}  // namespace

int runExperiment(const std::string& configPath, const ExperimentOptions& options) {
  Experiment e(loadExperiment(configPath), options);
  try {
    return e.run();
  } catch (const Interrupted&) {
    return 130;
  }
}

}  // namespace pl
