// `photonlab run EXPERIMENT.toml`: renders (or reuses) the reference, then every run over every
// seed, with checkpoints along the way, and writes images, metrics.csv and the resolved config.
// Layout of the results folder, and what resuming means, in docs/pages/reference/experiments.md.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "experiment/config.h"
#include "image/image.h"

namespace pl {

// One point of a run's convergence curve: what the render reports at a checkpoint.
using CheckpointInfo = RenderInfo;
using RunCheckpointFn = std::function<void(const ImageRGB&, const CheckpointInfo&)>;

// Renders `settings` on `scene`, calling `checkpoint` after 1, 2, 4, ... samples or passes and for
// the last image. Warnings (e.g. "no photons stored")
// are appended to `warnings`; the integrator's images beside the radiance (bdpt's techniques) to
// `extraImages`; what it says of its work (Integrator::notes) to `notes`.
ImageRGB renderRun(const Scene& scene, const RunSettings& settings, const RunCheckpointFn& checkpoint,
                   CheckpointInfo* final, std::vector<std::string>* warnings, uint64_t* nonFiniteSamples = nullptr,
                   std::vector<NamedImage>* extraImages = nullptr, std::vector<std::string>* notes = nullptr);

// The image metadata photonlab writes for a run (read back by `photonlab info IMAGE.exr`): the
// integrator's declared parameters (under their metadata keys), then what the render reports.
std::map<std::string, std::string> runMetadata(const RunSettings& settings, const CheckpointInfo& info,
                                               const std::string& scenePath);

// Every metadata key photonlab writes into an image besides the integrators' parameters (which
// are written under their own keys, ParamSpec::metaKey): `photonlab reference metadata` is made
// from this list, and a test holds runMetadata() to it.
struct MetadataKey {
  std::string key, doc;
};
const std::vector<MetadataKey>& metadataKeys();

struct ExperimentOptions {
  std::string out;        // results folder; empty = results/<name>/ (or results/<name>-N/, see the docs' Experiments page)
  std::string cache;      // reference cache folder; empty = .reference-cache/ beside the results folder
  bool force = false;     // overwrite a finished or different experiment in `out`
  bool quiet = false;
  int threads = -1;       // >= 0 overrides the config's threads
  // For running one experiment as many processes (scripts/cluster.py): list the (run, seed)
  // pairs; render only the reference; render only run `onlyRun` (1-based) with `onlySeed`, its
  // metrics rows going to its own folder (runs/NN-label/seed-S/metrics-rows.csv) instead of
  // metrics.csv, so that concurrent processes never write one file. A plain `run` afterwards
  // finds every pair finished and writes metrics.csv from those rows.
  bool listRuns = false;
  bool referenceOnly = false;
  int onlyRun = 0;
  uint64_t onlySeed = 0;
};

// Returns the process exit code: 0 done, 130 interrupted (finished runs kept, resumable).
// Throws Error for bad input (config, scene, reference file, folder conflicts).
int runExperiment(const std::string& configPath, const ExperimentOptions& options);

// metrics.csv's columns, in order (the first twelve are the documented interface).
const std::vector<std::string>& metricsColumns();

}  // namespace pl
