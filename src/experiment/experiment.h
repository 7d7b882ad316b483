// `photonlab run EXPERIMENT.toml`: renders (or reuses) the reference, then every run over every
// seed, with checkpoints along the way, and writes images, metrics.csv and the resolved config.
// Layout of the results folder, and what resuming means, in README ("Experiments").
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "experiment/config.h"
#include "render/image.h"

namespace pl {

// One point of a run's convergence curve.
struct CheckpointInfo {
  double seconds = 0.0;  // render time so far (checkpoint writing excluded)
  int spp = 0;           // samples per pixel (spp-based integrators)
  int passes = 0;        // photon passes (progressive integrators)
  double meanWork = 0.0;  // spp or passes per pixel on average: more than spp/passes when the
                          // budget cut the last pass short, after it reached some pixels
  uint64_t photons = 0;  // photon paths emitted so far (photon, ppm, sppm, pppm)
  double meanRadius = 0.0;
  bool last = false;         // the run's final image
  bool interrupted = false;  // stopped by SIGINT/SIGTERM: a partial result
  bool timeUp = false;       // stopped because the time budget was spent
};
using RunCheckpointFn = std::function<void(const ImageRGB&, const CheckpointInfo&)>;

// Renders `settings` on `scene`, calling `checkpoint` after 1, 2, 4, ... samples or passes and for
// the last image. Whatever the integrator family, one call. Warnings (e.g. "no photons stored")
// are appended to `warnings`.
ImageRGB renderRun(const Scene& scene, const RunSettings& settings, const RunCheckpointFn& checkpoint,
                   CheckpointInfo* final, std::vector<std::string>* warnings, uint64_t* nonFiniteSamples = nullptr);

// The image metadata photonlab writes for a run (read back by `photonlab info IMAGE.exr`).
std::map<std::string, std::string> runMetadata(const RunSettings& settings, const CheckpointInfo& info,
                                               const std::string& scenePath);

struct ExperimentOptions {
  std::string out;        // results folder; empty = results/<name>/ (or results/<name>-N/, see README)
  std::string cache;      // reference cache folder; empty = .reference-cache/ beside the results folder
  bool force = false;     // overwrite a finished or different experiment in `out`
  bool quiet = false;
  int threads = -1;       // >= 0 overrides the config's threads
};

// Returns the process exit code: 0 done, 130 interrupted (finished runs kept, resumable).
// Throws Error for bad input (config, scene, reference file, folder conflicts).
int runExperiment(const std::string& configPath, const ExperimentOptions& options);

// metrics.csv's columns, in order (the first twelve are the documented interface).
const std::vector<std::string>& metricsColumns();

}  // namespace pl
