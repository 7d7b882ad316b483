// photonlab command line: render, info, compare, bench. Every user error ends as one line on
// stderr ("photonlab: FILE: ELEMENT: what") and exit code 1; no output file is left behind.
#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <chrono>
#include <nlohmann/json.hpp>
#include <set>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/interrupt.h"
#include "experiment/experiment.h"
#include "io/image_io.h"
#include "cli/reference_pages.h"
#include "io/metrics.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"

namespace pl {
extern const char* const kGitRevision;  // generated at build time (scripts/git_revision.cmake)
int runBench(const std::string& scenePath, const std::string& glassScenePath, int threads, int spp);
int runLoadBench(const std::string& path, int repeats, Scene::BvhLayout bvh);
}

using namespace pl;
namespace fs = std::filesystem;

namespace {

// A metadata value as JSON: an integer or a finite real number when the whole text is one,
// else the text.
nlohmann::ordered_json jsonValue(const std::string& v) {
  if (v.empty()) return v;
  int64_t i;
  auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), i);
  if (ec == std::errc() && end == v.data() + v.size()) return i;
  uint64_t u;
  auto [uend, uec] = std::from_chars(v.data(), v.data() + v.size(), u);
  if (uec == std::errc() && uend == v.data() + v.size()) return u;
  char* dend = nullptr;
  double d = std::strtod(v.c_str(), &dend);
  if (dend == v.c_str() + v.size() && std::isfinite(d) && !std::isspace(static_cast<unsigned char>(v[0]))) return d;
  return v;
}

// --bvh on render and info: Embree's BVH layout (GltfLoadOptions::bvh).
Scene::BvhLayout bvhLayout = Scene::BvhLayout::Auto;

std::unique_ptr<Scene> loadScene(const std::string& path, GltfLoadOptions options = {}) {
  std::vector<std::string> warnings;
  options.bvh = bvhLayout;
  auto scene = loadGltf(path, &warnings, options);
  for (auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  return scene;
}

// Before anything renders: a render's minutes are not lost to an output it cannot write.
void checkOutputPath(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error(path + ": -o: is a folder; give a file name ending in .exr or .png");
  std::string ext = fs::path(path).extension().string();
  if (ext != ".exr" && ext != ".png") throw Error(path + ": -o: output must end in .exr or .png");
  fs::path dir = fs::path(path).parent_path();
  if (!dir.empty() && !fs::is_directory(dir, ec)) throw Error(path + ": -o: folder " + dir.string() + " does not exist");
  // Whether a file can be made there, tried (permission bits do not say it for root, nor for a
  // read-only or virtual file system): the image is written to a temporary file beside it and
  // renamed into place (io/image_io.cpp).
  const fs::path probe = (dir.empty() ? fs::path(".") : dir) / (".photonlab-write-test-" + std::to_string(getpid()));
  const int fd = open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY, 0600);
  if (fd < 0)
    throw Error(path + ": -o: cannot write in folder " + (dir.empty() ? std::string(".") : dir.string()) + " (" +
                std::strerror(errno) + ")");
  close(fd);
  unlink(probe.c_str());
}

// "Did you mean": the known word nearest `word` in edits (Levenshtein), if it is near enough
// to be a typing slip (at most a third of its letters), else "".
std::string nearest(const std::string& word, const std::vector<std::string>& known) {
  auto distance = [](const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diagonal = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        const size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  size_t bestDistance = std::max<size_t>(1, word.size() / 3) + 1;
  for (const std::string& k : known) {
    const size_t d = distance(word, k);
    if (d < bestDistance) best = k, bestDistance = d;
  }
  return best;
}

// --exposure EV|auto.
Display parseExposure(const std::string& text) {
  Display d;
  if (text == "auto") {
    d.autoExposure = true;
    return d;
  }
  char* end = nullptr;
  d.exposure = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(d.exposure) || std::abs(d.exposure) > 64)
    throw Error("--exposure: must be auto or a number of EV from -64 to 64, got '" + text + "'");
  return d;
}

// Parses "X,Y,Z" (n numbers separated by commas) for `flag`.
std::vector<float> parseNumbers(const std::string& flag, const std::string& text, size_t n, const char* shape) {
  std::vector<float> v;
  size_t start = 0;
  for (;;) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    const double x = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(x)) v.clear(), start = std::string::npos;
    else v.push_back(float(x));
    if (comma == std::string::npos || start == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != n) throw Error(flag + ": expected " + shape + " (" + std::to_string(n) + " numbers separated by commas), got '" + text + "'");
  return v;
}

// Interrupted (SIGINT/SIGTERM): the estimate reached so far goes to OUT.partial.exr (never over
// OUT itself, which a script may take for a finished result), marked partial="1"; exit 130.
// Before any pixel has an estimate (in photon tracing, say) the image would be all black, a
// picture of nothing: then nothing is written, and the message says so.
int writePartial(const std::vector<std::string>& outputs, const ImageRGB& image, std::map<std::string, std::string> meta,
                 double seconds, const Display& display) {
  if (std::none_of(image.data.begin(), image.data.end(), [](float v) { return v != 0.0f && std::isfinite(v); })) {
    std::fprintf(stderr, "photonlab: interrupted after %.2f s, before any pixel had an estimate: no image written\n", seconds);
    return 130;
  }
  meta["partial"] = "1";
  for (auto& o : outputs) {
    fs::path p(o);
    std::string partial = (p.parent_path() / (p.stem().string() + ".partial" + p.extension().string())).string();
    writeImage(partial, image, meta, display);
    std::fprintf(stderr, "photonlab: interrupted after %.2f s: partial image written to %s\n", seconds, partial.c_str());
  }
  return 130;
}

// photonlab tonemap IN.exr -o OUT.png: the EXR's radiance through another exposure or curve,
// with the EXR's metadata (what was rendered, how) beside the PNG's own display settings.
int cmdTonemap(const std::string& input, const std::string& output, const std::string& exposure, const std::string& curve) {
  if (fs::path(output).extension() != ".png") throw Error(output + ": -o: tonemap writes a .png");
  checkOutputPath(output);
  if (fs::path(input).extension() != ".exr")
    throw Error(input + ": tonemap develops a linear image (.exr); a PNG's values are display values already");
  Display display = parseExposure(exposure);
  try {
    display.curve = parseToneCurve(curve);
  } catch (const Error& e) {
    throw Error(std::string("--tonemap: ") + e.what());
  }
  const ImageRGB image = readImage(input);
  std::map<std::string, std::string> meta = readImageMetadata(input);
  for (const char* key : {"exposure", "exposure_rule", "tonemap"}) meta.erase(key);
  writeImage(output, image, meta, display);
  std::fprintf(stderr, "tonemap: %s -> %s (%s EV%s, %s)\n", input.c_str(), output.c_str(),
               formatNumber(display.autoExposure ? meteredExposure(image.data.data(), image.data.size() / 3) : display.exposure).c_str(),
               display.autoExposure ? ", metered" : "", toneCurveName(display.curve));
  return 0;
}

// Any integrator, through renderRun() and runMetadata(), as `photonlab run` does. With
// `checkpoints` (integrators counted in passes), OUT.pass-NNNN.ext after passes 1, 2, 4, ... and
// the last.
int cmdRender(const std::string& scenePath, const std::vector<std::string>& outputs, RunSettings s, bool checkpoints,
              bool quiet, const Display& display, const std::string& notice) {
  for (auto& o : outputs) checkOutputPath(o);
  GltfLoadOptions load;
  load.camera = s.image.camera;
  load.view = s.image.view;
  load.environment = s.image.environment;
  load.readImage = readEnvironmentMap;
  load.units = s.image.units;
  if (s.image.width > 0 && s.image.height > 0) load.aspect = float(s.image.width) / float(s.image.height);
  auto scene = loadScene(scenePath, load);
  if (!notice.empty()) std::fprintf(stderr, "warning: %s\n", notice.c_str());
  // From here on an interrupt stops the render at its next pixel, chunk of photons or slice of
  // the tree build, and the image so far is written (before, it ended the process at once).
  setInterruptCooperative(true);
  resolveResolution(scene->camera(), s.image);
  const bool progressive = s.budgetUnit() == "passes";
  // Scene-derived defaults (the estimate's radius), resolved before rendering so that the
  // metadata records them, and said in the summary line (before rendering too on a terminal: a
  // log gets only the summary, or one error line).
  std::string radius;
  if (s.entry().resolve) radius = s.entry().resolve(*scene, s.image.width, s.image.height, s.params);
  if (!quiet && isatty(STDERR_FILENO)) {  // beside the progress bar
    const std::string unit = s.budgetUnit();
    std::string work = s.params.isSet(unit) ? std::to_string(s.params.integer(unit)) + " " + unit : "";
    if (s.image.timeLimit > 0)
      work = work.empty() ? "for " + formatNumber(s.image.timeLimit) + " s"
                          : work + " or " + formatNumber(s.image.timeLimit) + " s, whichever ends first";
    std::fprintf(stderr, "%s: rendering %dx%d, %s%s\n", s.integrator.c_str(), s.image.width, s.image.height,
                 work.empty() ? "until interrupted" : work.c_str(), radius.empty() ? "" : ("; " + radius).c_str());
  }
  RunCheckpointFn checkpoint;
  if (checkpoints) {
    checkpoint = [&](const ImageRGB& image, const CheckpointInfo& info) {
      for (auto& o : outputs) {
        fs::path p(o);
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, ".pass-%04d", info.passes);
        writeImage((p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string(), image,
                   runMetadata(s, info, scenePath), display);
      }
    };
  }
  CheckpointInfo info;
  std::vector<std::string> warnings;
  uint64_t nonFinite = 0;
  std::vector<NamedImage> extras;
  std::vector<std::string> notes;
  ImageRGB image = renderRun(*scene, s, checkpoint, &info, &warnings, &nonFinite, &extras, &notes);
  for (auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  auto meta = runMetadata(s, info, scenePath);
  if (info.interrupted) return writePartial(outputs, image, meta, info.seconds, display);
  if (s.image.sliced()) {
    for (auto& o : outputs) writeSlice(o, *info.slice, meta);
    if (!quiet)
      std::fprintf(stderr, "%s: %dx%d, %s %d:%d%s of the render, %.2f s -> %s\n", s.integrator.c_str(), s.image.width,
                   s.image.height, progressive ? "passes" : "samples", s.image.rangeBegin, s.image.rangeEnd,
                   s.image.rangeStep > 1 ? (":" + std::to_string(s.image.rangeStep)).c_str() : "", info.seconds,
                   outputs.front().c_str());
    return 0;
  }
  // The images beside the radiance (bdpt's per technique) are shown at the radiance's exposure,
  // so that they compare.
  Display beside = display;
  if (display.autoExposure) beside.autoExposure = false, beside.exposure = meteredExposure(image.data.data(), image.data.size() / 3);
  for (auto& o : outputs) {
    writeImage(o, image, meta, display);
    fs::path p(o);
    for (const NamedImage& e : extras)  // OUT.s1t2.exr beside OUT.exr
      writeImage((p.parent_path() / (p.stem().string() + "." + e.name + p.extension().string())).string(), e.image, meta,
                 beside);
  }
  if (nonFinite) std::fprintf(stderr, "warning: %llu non-finite samples discarded\n", (unsigned long long)nonFinite);
  if (quiet) return 0;
  for (auto& n : notes) std::fprintf(stderr, "%s: %s\n", s.integrator.c_str(), n.c_str());
  // The work done: "12 passes", or "12.4 passes (the budget ended pass 13 after 40% of the pixels)".
  const int whole = progressive ? info.passes : info.spp;
  std::string work = std::to_string(whole) + (progressive ? " passes" : " spp");
  if (info.meanWork != whole) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.2f %s (the last one reached %.0f%% of the pixels)", info.meanWork,
                  progressive ? "passes" : "spp", 100.0 * (info.meanWork - whole));
    work = buf;
  }
  std::string budget = s.image.timeLimit > 0 ? " of a " + formatNumber(s.image.timeLimit) + " s budget" : "";
  // Hachisuka & Jensen's visibility: how many of the photons were of use to this view.
  const std::string visibility =
      (info.visibleFraction >= 0 ? ", " + percentText(info.visibleFraction) + " of the usable photons near a visible point" : "") +
      (info.visiblePaths >= 0 ? " (adaptive chain; " + percentText(info.visiblePaths) + " of uniform paths visible)" : "");
  if (progressive)
    std::fprintf(stderr, "%s: %dx%d, %s, %llu photon paths, %.2f s%s, %s, mean radius at the end %g m%s -> %s\n",
                 s.integrator.c_str(), s.image.width, s.image.height, work.c_str(), (unsigned long long)info.photons,
                 info.seconds, budget.c_str(), radius.c_str(), info.meanRadius, visibility.c_str(), outputs.front().c_str());
  else
    std::fprintf(stderr, "%s: %dx%d, %s, %.2f s%s%s -> %s\n", s.integrator.c_str(), s.image.width, s.image.height,
                 work.c_str(), info.seconds, budget.c_str(),
                 radius.empty() ? "" : (", " + radius + (info.meanRadius > 0 ? " (mean " + formatNumber(info.meanRadius) + " m)" : "")).c_str(),
                 outputs.front().c_str());
  return 0;
}

// An image's photonlab metadata as one JSON object: numbers as JSON numbers, text as strings.
int cmdImageInfo(const std::string& imagePath) {
  auto meta = readImageMetadata(imagePath);
  ImageRGB image = readImage(imagePath);
  // Values that are text even when they happen to look like a number (a hash of digits only).
  static const std::set<std::string> text = {"integrator", "scene", "kernel", "aov", "label", "experiment",
                                             "reference_file", "cache_key", "git_revision", "cpu", "tonemap",
                                             "reference_integrator", "reference_git_revision"};
  nlohmann::ordered_json j;
  j["width"] = image.width;
  j["height"] = image.height;
  for (auto& [key, value] : meta) {
    if (key == "width" || key == "height") continue;
    j[key] = text.count(key) ? nlohmann::ordered_json(value) : jsonValue(value);
  }
  // One line, with a space after ':' and ',' (as `compare` prints).
  std::string line = "{";
  for (auto it = j.begin(); it != j.end(); ++it)
    line += (it == j.begin() ? "" : ", ") + nlohmann::ordered_json(it.key()).dump() + ": " + it.value().dump();
  std::printf("%s}\n", line.c_str());
  return 0;
}

int cmdInfo(const std::string& scenePath, const std::string& units) {
  std::string ext = fs::path(scenePath).extension().string();
  if (ext == ".exr" || ext == ".png") return cmdImageInfo(scenePath);
  // Any loadable file, with the sky a file without lights gets.
  GltfLoadOptions load;
  load.readImage = readEnvironmentMap;
  load.units = units;
  auto scene = loadScene(scenePath, load);
  const Bounds& b = scene->bounds();
  std::printf("scene: %s\n", scenePath.c_str());
  std::printf("triangles: %zu", scene->triangleCount());
  if (scene->instanceCount() > 0)
    std::printf(" (%zu stored: meshes that several nodes place are stored once, %zu instances)", scene->storedTriangleCount(),
                scene->instanceCount());
  if (scene->compactBvh())
    std::printf("\nBVH: compact (--bvh; the default from 1048576 stored triangles), %zu of the stored triangles "
                "paired into quads\n", scene->pairedTriangleCount());
  else
    std::printf("\nBVH: fast (--bvh compact halves its memory)\n");
  if (b.empty()) std::printf("bounds: none (no triangles)\n");
  else std::printf("bounds: [%g, %g, %g] - [%g, %g, %g] m\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  auto describe = [](const Camera& c) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "position [%g, %g, %g], forward [%g, %g, %g], yfov %g rad, aspect %g", c.position.x,
                  c.position.y, c.position.z, c.forward.x, c.forward.y, c.forward.z, c.yfov, c.aspectRatio);
    return std::string(buf);
  };
  std::printf("cameras: %zu in the file (--camera N picks one)\n", scene->fileCameras().size());
  for (size_t i = 0; i < scene->fileCameras().size(); ++i)
    std::printf("  %zu: %s: %s\n", i, scene->fileCameras()[i].name.c_str(), describe(scene->fileCameras()[i].camera).c_str());
  std::printf("camera used by default: %s: %s\n", scene->cameraSource.c_str(), describe(scene->camera()).c_str());
  std::printf("materials: %zu\n", scene->materials().size());
  for (auto& m : scene->materials())
    std::printf("  %-24s %-11s%s\n", m.name.c_str(), m.bsdf->name(),
                isBlack(m.emission) ? "" : (" emits Le = [" + formatNumber(m.emission.r) + ", " + formatNumber(m.emission.g) + ", " + formatNumber(m.emission.b) + "] W/(m2 sr)").c_str());
  // Area lights are one per emissive triangle: summarise them by kind.
  std::map<std::string, std::pair<int, Spectrum>> byKind;
  for (auto& l : scene->lights()) {
    auto& e = byKind[l->name()];
    e.first++;
    e.second += l->power();
  }
  std::printf("units: %s\n", scene->units.c_str());
  std::printf("lights: %zu\n", scene->lights().size());
  for (auto& [kind, e] : byKind)
    std::printf("  %-12s x%-6d power [%g, %g, %g] W\n", kind.c_str(), e.first, e.second.r, e.second.g, e.second.b);
  if (const EnvironmentLight* env = scene->environment())
    std::printf("environment: %s (%dx%d texels), integral of L over the sphere [%g, %g, %g] W/m2, power through the "
                "bounding disc [%g, %g, %g] W\n",
                scene->environmentSource.c_str(), env->map().width, env->map().height, env->integral().r,
                env->integral().g, env->integral().b, env->power().r, env->power().g, env->power().b);
  else
    std::printf("environment: none (--env adds one)\n");
  Spectrum total = scene->totalPower();
  std::printf("total power: [%g, %g, %g] W\n", total.r, total.g, total.b);
  return 0;
}

// "A:B" or "A:B:K" with 0 ≤ A < B and K ≥ 1 (K: every K-th sample or pass from A).
void parseRange(const std::string& flag, const std::string& text, int* begin, int* end, int* step) {
  const std::string expected = flag + ": expected A:B or A:B:K with 0 <= A < B and K >= 1, got '" + text + "'";
  std::vector<std::string> fields;
  size_t start = 0;
  for (size_t colon; (colon = text.find(':', start)) != std::string::npos; start = colon + 1) fields.push_back(text.substr(start, colon - start));
  fields.push_back(text.substr(start));
  if (fields.size() < 2 || fields.size() > 3) throw Error(expected);
  auto number = [&](const std::string& t) {
    size_t used = 0;
    long long v = -1;
    try {
      v = std::stoll(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != t.size() || t.empty() || v < 0 || v > (1 << 24)) throw Error(expected);
    return int(v);
  };
  *begin = number(fields[0]);
  *end = number(fields[1]);
  *step = fields.size() == 3 ? number(fields[2]) : 1;
  if (*begin >= *end || *step < 1) throw Error(expected);
}

// `photonlab merge`: slices of one render (same scene, settings, seed, build) tiling [A, B)
// without gaps or overlaps, added up exactly in range order (core/exact_sum.h): the result is
// bit for bit the single-process render of samples (passes) A to B.
int cmdMerge(const std::vector<std::string>& paths, const std::string& output, bool partialOutput) {
  struct Part {
    std::string path;
    RenderSlice slice;
    std::map<std::string, std::string> meta;
  };
  checkOutputPath(output);
  std::vector<Part> parts;
  for (const std::string& p : paths) parts.push_back({p, readSlice(p), readImageMetadata(p)});
  // What differs between slices of one render: their own work, time and range; everything
  // else (scene, integrator, every parameter, seed, size, spectral, build) must agree.
  std::set<std::string> own = {"seconds", "range_begin", "range_end", "range_step", "spp", "passes", "mean_spp", "mean_passes",
                               "photons", "mean_radius", "time_up", "merged_slices", "visible_photons", "visible_paths"};
  const Part& first = parts.front();
  // "radius" is the radius reached (per slice) unless the integrator declares it as a parameter.
  const IntegratorEntry* entry = first.meta.count("integrator") ? findIntegrator(first.meta.at("integrator")) : nullptr;
  if (entry && std::none_of(entry->params.begin(), entry->params.end(), [](const ParamSpec& p) { return p.metaKey() == "radius"; }))
    own.insert("radius");
  for (const Part& p : parts) {
    if (p.meta.count("partial")) throw Error(p.path + ": an interrupted slice (metadata partial = 1); render it again");
    // The telling differences first.
    std::vector<std::string> keys = {"integrator", "scene", "seed", "width", "height", "git_revision"};
    for (const auto* m : {&first.meta, &p.meta})
      for (auto& [k, v] : *m)
        if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
    for (const std::string& k : keys) {
      if (own.count(k)) continue;
      auto a = first.meta.find(k), b = p.meta.find(k);
      std::string va = a == first.meta.end() ? "(none)" : a->second, vb = b == p.meta.end() ? "(none)" : b->second;
      if (va != vb)
        throw Error(p.path + ": not a slice of the same render as " + first.path + " (" + k + " " + vb + " against " + va + ")");
    }
  }
  std::sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) { return a.slice.begin < b.slice.begin; });
  const std::string unit = first.meta.count("passes") ? "passes" : "samples";
  // Together the slices must cover [lo, hi) once each: every sample (pass) of it, no other.
  int lo = INT32_MAX, hi = 0;
  for (const Part& p : parts) lo = std::min(lo, p.slice.begin), hi = std::max(hi, p.slice.end);
  std::vector<int> owner(size_t(hi - lo), -1);
  for (size_t k = 0; k < parts.size(); ++k) {
    const RenderSlice& s = parts[k].slice;
    for (int i = s.begin; i < s.end; i += s.step) {
      int& o = owner[size_t(i - lo)];
      if (o >= 0)
        throw Error(parts[k].path + ": overlaps " + parts[size_t(o)].path + " (both hold " + unit + " " + std::to_string(i) + ")");
      o = int(k);
    }
  }
  for (int i = lo; i < hi; ++i)
    if (owner[size_t(i - lo)] < 0) {
      int j = i;
      while (j < hi && owner[size_t(j - lo)] < 0) ++j;
      throw Error(paths.front() + ": " + unit + " " + std::to_string(i) + ":" + std::to_string(j) +
                  " are in none of the slices (they cover " + std::to_string(lo) + ":" + std::to_string(hi) + ")");
    }
  RenderSlice merged = parts.front().slice;
  merged.begin = lo, merged.end = hi, merged.step = 1;
  double seconds = 0;
  uint64_t photons = 0;
  // Σ visible_photons × photons, Σ visible_paths × photons: the slices' visibility weighted by their photon paths
  double visible = 0, visiblePaths = 0;
  int slices = 0;  // the original slices, through merges of merges
  for (size_t i = 0; i < parts.size(); ++i) {
    const RenderSlice& s = parts[i].slice;
    slices += parts[i].meta.count("merged_slices") ? std::stoi(parts[i].meta.at("merged_slices")) : 1;
    seconds += std::stod(parts[i].meta.count("seconds") ? parts[i].meta.at("seconds") : "0");
    if (parts[i].meta.count("photons")) {
      photons += std::stoull(parts[i].meta.at("photons"));
      if (parts[i].meta.count("visible_photons"))
        visible += std::stod(parts[i].meta.at("visible_photons")) * std::stod(parts[i].meta.at("photons"));
      if (parts[i].meta.count("visible_paths"))
        visiblePaths += std::stod(parts[i].meta.at("visible_paths")) * std::stod(parts[i].meta.at("photons"));
    }
    if (i == 0) continue;
    if (s.sums.size() != merged.sums.size() || s.splats.size() != merged.splats.size() || s.counts.size() != merged.counts.size())
      throw Error(parts[i].path + ": not a slice of the same render as " + parts.front().path + " (its sums differ in kind or size)");
    for (size_t k = 0; k < merged.sums.size(); ++k) merged.sums[k].add(s.sums[k]);
    for (size_t k = 0; k < merged.splats.size(); ++k) merged.splats[k].add(s.splats[k]);
    for (size_t k = 0; k < merged.counts.size(); ++k) merged.counts[k] += s.counts[k];
  }
  std::map<std::string, std::string> meta = parts.back().meta;  // the last slice's radius is the render's
  meta.erase("range_begin"), meta.erase("range_end"), meta.erase("range_step");
  meta["seconds"] = formatNumber(seconds);
  meta[unit == "passes" ? "passes" : "spp"] = std::to_string(merged.end - merged.begin);
  if (photons) meta["photons"] = std::to_string(photons);
  if (photons && meta.count("visible_photons")) meta["visible_photons"] = formatNumber(visible / double(photons));
  if (photons && meta.count("visible_paths")) meta["visible_paths"] = formatNumber(visiblePaths / double(photons));
  meta["merged_slices"] = std::to_string(slices);
  if (partialOutput) writeSlice(output, merged, meta);
  else {
    if (merged.begin != 0) meta["range_begin"] = std::to_string(merged.begin), meta["range_end"] = std::to_string(merged.end);
    writeImage(output, merged.mean(), meta);
  }
  std::fprintf(stderr, "merge: %zu slices, %s %d:%d -> %s\n", parts.size(), unit.c_str(), merged.begin, merged.end,
               output.c_str());
  return 0;
}

int cmdCompare(const std::string& imagePath, const std::string& referencePath) {
  // Errors are about radiance: a PNG holds display values (exposed, tone-mapped, clamped to
  // [0, 1], sRGB-encoded). Against a linear EXR that is no comparison at all; two PNGs are
  // compared after undoing the sRGB curve, and the output says so.
  const bool imageDisplay = isDisplayReferred(imagePath), referenceDisplay = isDisplayReferred(referencePath);
  if (imageDisplay != referenceDisplay) {
    const std::string& png = imageDisplay ? imagePath : referencePath;
    const std::string& exr = imageDisplay ? referencePath : imagePath;
    throw Error(png + ": an 8-bit display image (sRGB, clamped to [0, 1]) cannot be compared with the linear " + exr +
                ": compare the EXR rendered with it (photonlab render ... -o x.exr -o x.png)");
  }
  ImageRGB image = readImage(imagePath), reference = readImage(referencePath);
  if (imageDisplay) {
    for (ImageRGB* img : {&image, &reference})
      for (float& v : img->data) v = srgbDecode(v);
    std::fprintf(stderr, "compare: both images are display-referred (PNG): compared after decoding sRGB to linear; "
                         "values above 1 were clipped when they were written\n");
  }
  ErrorMetrics m = compareImages(image, reference);
  std::printf("{\"rmse\": %s, \"relmse\": %s, \"mae\": %s, \"mean_ratio\": %s%s}\n", formatNumber(m.rmse).c_str(),
              formatNumber(m.relmse).c_str(), formatNumber(m.mae).c_str(), formatNumber(m.meanRatio).c_str(),
              imageDisplay ? ", \"decoded_srgb\": true" : "");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Keep freed memory in the heap for the next allocation instead of handing it back to the
  // kernel: every photon-tracing pass writes tens of MB of photon buffers, and fresh pages
  // fault in (zeroed by the kernel) on first touch (docs: Performance). Blocks above 32 MB
  // (large maps, films) are still mmapped.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
  CLI::App app{"photonlab: light transport by photon mapping, with a path-traced ground truth"};
  app.set_version_flag("--version", std::string("photonlab ") + kGitRevision);
  app.require_subcommand(0, 1);

  std::string scenePath, integratorName = "path";
  std::vector<std::string> outputs;
  RenderOptions options;
  bool quiet = false;
  auto* render = app.add_subcommand("render", "Render a glTF scene to EXR (linear) and/or PNG (sRGB)");
  render->add_option("scene", scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
  render->add_option("-o,--output", outputs, "Output image(s): .exr or .png; repeat for both")->required();
  render->add_option("--integrator", integratorName, "One of: " + integratorList() + " (photonlab integrators: what each does and takes)")
      ->capture_default_str();
  auto* widthOpt = render->add_option("--width", options.width, "Image width in pixels (height follows the camera's aspect)");
  auto* heightOpt = render->add_option("--height", options.height, "Image height in pixels");
  render->add_option("--camera", options.camera,
                     "Which of the file's cameras renders, as photonlab info numbers them (default the first; a file "
                     "without one: an automatic three-quarter view)")
      ->check(CLI::NonNegativeNumber);
  std::string lookFrom, lookAt, upText, orbitText;
  float fov = 0;
  render->add_option("--look-from", lookFrom, "X,Y,Z: the camera's position, looking at --look-at (instead of the file's camera)");
  render->add_option("--look-at", lookAt, "X,Y,Z: the point the --look-from camera looks at");
  render->add_option("--up", upText, "X,Y,Z: the image's up direction for --look-from (default 0,1,0)");
  render->add_option("--orbit", orbitText,
                     "AZ,EL: degrees; the scene's bounds framed whole from azimuth AZ (from +Z towards +X) and "
                     "elevation EL (the automatic view is 45,30), instead of the file's camera");
  auto* fovOpt = render->add_option("--fov", fov,
                                    "Vertical field of view in degrees (default: the camera's own; 40 for the automatic "
                                    "view, --orbit and --look-from)");
  std::string envText;
  float envRotate = 0.0f, envScale = 1.0f;
  render->add_option("--env", envText,
                     "Environment light: R,G,B (or one number) radiance in W/(m2 sr), overcast (the CIE overcast sky "
                     "of mean radiance 1, the default where a file has no light), or an equirectangular map "
                     "(EXR, HDR, PFM; PNG/JPEG are sRGB-decoded); replaces the file's");
  auto* envRotateOpt = render->add_option("--env-rotate", envRotate, "Degrees the --env map turns about +Y");
  auto* envScaleOpt = render->add_option("--env-scale", envScale, "Factor on the --env radiance");
  render->add_option("--units", options.units,
                     "Light values in the file: radiometric (W/sr, W/m2, W/(m2 sr)) or photometric (cd, lx, nits; /683 lm/W). "
                     "Default: the file's asset.extras.photonlab.units, else photometric")
      ->check(CLI::IsMember({"radiometric", "photometric"}));
  auto* timeOpt = render->add_option("--time", options.timeLimit,
                                     "Time budget in seconds: the render stops when it is spent, wherever it is");
  int64_t seed = 1;
  render->add_option("--seed", seed, "Random seed, 0 or more (experiments' references use -1)")->capture_default_str();
  render->add_option("--threads", options.threads, "Worker threads (0 = all cores)")->capture_default_str();
  render->add_flag("-q,--quiet", quiet, "No summary line");
  render->add_flag("--spectral", options.spectral,
                   "Spectral rendering: paths carry wavelengths, the film integrates the CIE 1931 curves");
  // One flag per declared integrator parameter (integrators/registry.h), read as text and
  // validated by the chosen integrator's declaration: the same words as an experiment's TOML.
  std::map<std::string, std::string> paramText;
  std::map<std::string, CLI::Option*> paramOpts;
  for (const IntegratorEntry* e : integrators())
    for (const ParamSpec& p : e->params) {
      if (paramOpts.count(p.name) || p.name == "aov") continue;
      // One line per distinct meaning ("photon: fixed radius; ppm, pppm, sppm: initial radius").
      std::vector<std::pair<std::string, std::string>> meanings;  // doc (default) -> integrators
      for (const IntegratorEntry* f : integrators())
        for (const ParamSpec& q : f->params) {
          if (q.name != p.name) continue;
          std::string meaning = q.doc + " (default " + (q.defaultDoc.empty() ? q.defaultValue : q.defaultDoc) + ")";
          auto it = std::find_if(meanings.begin(), meanings.end(), [&](auto& m) { return m.first == meaning; });
          if (it == meanings.end()) meanings.push_back({meaning, f->name});
          else it->second += ", " + f->name;
        }
      std::string help;
      for (auto& [meaning, who] : meanings) help += (help.empty() ? "" : "; ") + who + ": " + meaning;
      const char* type = p.type == ParamType::Integer ? "INT" : p.type == ParamType::Real ? "FLOAT" : "";
      std::string choices;
      for (auto& c : p.choices) choices += (choices.empty() ? "" : "|") + c;
      paramOpts[p.name] = render->add_option(p.flag(), paramText[p.name], help)->type_name(p.type == ParamType::Choice ? choices : type);
    }
  std::string aov;
  render->add_option("--aov", aov,
                     "Debug image instead of radiance: nan (fraction of discarded non-finite samples); "
                     "photons | radius [" + integratorsTaking("aov") + "]");
  Display display;
  std::string toneCurve = "clamp";
  std::string exposureText = "auto";
  auto* exposureOpt = render->add_option("--exposure", exposureText,
                                         "PNG only: exposure in EV (linear values times 2^EV), or auto: the lit pixels' "
                                         "log-average luminance to middle grey 0.18; EXR stays linear")
                          ->capture_default_str();
  auto* tonemapOpt = render->add_option("--tonemap", toneCurve, "PNG only: clamp | aces (a filmic curve that rolls highlights off)")
      ->capture_default_str();
  std::string sampleRange, passRange;
  render->add_option("--sample-range", sampleRange,
                     "A:B: render only samples A..B-1 of the full render, keyed as it keys them, into an EXR of their "
                     "exact sums (photonlab merge adds slices up) [" + integratorsSlicedBy("spp") + "]");
  render->add_option("--pass-range", passRange, "A:B: the same in passes [" + integratorsSlicedBy("passes") + "]");
  bool checkpoints = false;
  render->add_flag("--checkpoints", checkpoints,
                   "Integrators counted in passes: also write OUT.pass-N.exr after passes 1, 2, 4, 8, ...");

  auto* integratorsCmd = app.add_subcommand("integrators", "The integrators and their parameters (--markdown: as tables)");
  bool markdown = false;
  integratorsCmd->add_flag("--markdown", markdown, "Markdown tables, as the documentation's Integrators reference");

  auto* info = app.add_subcommand("info", "Triangles, bounds, cameras, materials, lights with their power (W); "
                                          "or an image's metadata as JSON");
  std::string infoScene;
  info->add_option("file", infoScene, "glTF 2.0 scene, or an .exr written by photonlab")->required();
  std::string infoUnits;
  info->add_option("--units", infoUnits, "As render's --units")->check(CLI::IsMember({"radiometric", "photometric"}));

  auto* compare = app.add_subcommand("compare", "Error metrics of IMAGE against REFERENCE, as one JSON object");
  std::string imagePath, referencePath;
  compare->add_option("image", imagePath)->required();
  compare->add_option("reference", referencePath)->required();

  auto* tonemap = app.add_subcommand("tonemap", "Develop a linear image (.exr) into a PNG again: exposure and tone curve, "
                                                "its metadata kept");
  std::string tonemapInput, tonemapOutput, tonemapExposure = "auto", tonemapCurve = "clamp";
  tonemap->add_option("image", tonemapInput, "A linear image, as photonlab writes it (.exr)")->required();
  tonemap->add_option("-o,--output", tonemapOutput, "The PNG")->required();
  tonemap->add_option("--exposure", tonemapExposure, "Exposure in EV, or auto (as render's --exposure)")->capture_default_str();
  tonemap->add_option("--tonemap", tonemapCurve, "clamp | aces (as render's --tonemap)")->capture_default_str();

  auto* merge = app.add_subcommand("merge", "Add render slices (--sample-range, --pass-range) up into one image, bit for bit "
                                          "the single-process render of their union");
  std::vector<std::string> mergeParts;
  std::string mergeOutput;
  bool mergePartial = false;
  merge->add_option("parts", mergeParts, "Slice EXRs, in any order")->required();
  merge->add_option("-o,--output", mergeOutput, "The merged image (.exr or .png), or with --partial a slice again (.exr)")
      ->required();
  merge->add_flag("--partial", mergePartial, "Write a slice (exact sums) instead of an image, to merge further");

  auto* run = app.add_subcommand("run", "Run an experiment (experiments/*.toml): reference, runs, checkpoints, metrics.csv");
  std::string experimentPath;
  ExperimentOptions experiment;
  run->add_option("experiment", experimentPath, "Experiment config (TOML)")->required();
  run->add_option("--out", experiment.out, "Results folder (default results/<name>/)");
  run->add_option("--cache", experiment.cache, "Reference cache folder (default .reference-cache/ beside the results)");
  run->add_flag("--force", experiment.force, "Overwrite a finished or different experiment in the results folder");
  run->add_option("--threads", experiment.threads, "Worker threads, overriding the config (0 = all cores)");
  run->add_flag("-q,--quiet", experiment.quiet, "Only warnings and errors");
  run->add_flag("--list-runs", experiment.listRuns, "Print the (run, seed) pairs, \"RUN SEED\" per line, and stop");
  run->add_flag("--reference-only", experiment.referenceOnly, "Render (or find in the cache) the reference only");
  std::string onlyRun;
  run->add_option("--only", onlyRun,
                  "RUN:SEED: that run and seed alone, its metrics rows in its own folder (for many processes at once, "
                  "scripts/cluster.py); a plain run afterwards collects them into metrics.csv");

  auto* bench = app.add_subcommand("bench", "Embree ray rate and path-tracer throughput (documentation: Performance)");
  std::string benchScene = std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf";
  int benchThreads = 0, benchSpp = 8;
  bench->add_option("--scene", benchScene)->capture_default_str();
  std::string benchGlassScene = std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-spheres.gltf";
  bench->add_option("--glass-scene", benchGlassScene,
                    "The mirror-and-glass Cornell box: path-tracer rates and the relMSE after 10 s")
      ->capture_default_str();
  bench->add_option("--threads", benchThreads, "Threads for the multi-threaded column (0 = all cores)");
  bench->add_option("--spp", benchSpp, "Path-tracer samples per pixel at 256x256")->capture_default_str();
  std::string benchLoad;
  int benchRepeats = 3;
  bench->add_option("--load", benchLoad,
                    "Instead: how fast this glTF file loads (until it can be traced) and its peak memory against the "
                    "file's geometry (scripts/load_benchmark.py)");
  bench->add_option("--repeats", benchRepeats, "With --load: loads, the best time and the largest peak reported")
      ->check(CLI::Range(1, 100))->capture_default_str();
  std::string bvhText = "auto";
  const std::string bvhHelp = "Embree's BVH: fast, compact (triangles paired into quads: less than half its memory), or auto (compact "
                              "from 2^20 stored triangles on)";
  for (CLI::App* cmd : {render, info, bench}) cmd->add_option("--bvh", bvhText, bvhHelp)->check(CLI::IsMember({"auto", "fast", "compact"}));

  auto* referenceCmd = app.add_subcommand("reference", "Print a page of the documentation's reference, generated from the code "
                                                       "(Markdown: docs/pages/reference/PAGE.md is this output)");
  std::string referenceName;
  referenceCmd->add_option("page", referenceName, "cli | integrators | experiment | metadata")
      ->required()
      ->check(CLI::IsMember(referencePageNames()));
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) sub->footer(helpFooter(sub->get_name()));
  app.footer(helpFooter(""));

  // Words the parser does not know come back to us (allow_extras) so that a typing slip gets a
  // suggestion: "unknown option --intergrator (did you mean --integrator?)".
  app.allow_extras();
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) sub->allow_extras();
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "photonlab: %s\n", e.what());
    return 1;
  }
  {
    CLI::App* used = &app;
    for (CLI::App* sub : app.get_subcommands()) used = sub;
    const std::vector<std::string> extras = used->remaining();
    if (!extras.empty()) {
      const std::string& word = extras.front();
      const std::string where = used == &app ? "photonlab" : "photonlab " + used->get_name();
      std::vector<std::string> known;
      std::string what;
      if (word.size() > 1 && word[0] == '-') {
        what = "unknown option " + word;
        for (const CLI::Option* opt : used->get_options())
          for (const std::string& name : opt->get_lnames()) known.push_back("--" + name);
      } else {
        what = used == &app ? "unknown command '" + word + "'" : "unexpected argument '" + word + "'";
        if (used == &app)
          for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) known.push_back(sub->get_name());
      }
      const std::string guess = nearest(word.substr(0, word.find('=')), known);
      std::fprintf(stderr, "%s: %s%s (%s --help lists %s)\n", where.c_str(), what.c_str(),
                   guess.empty() ? "" : (" (did you mean " + guess + "?)").c_str(), where.c_str(),
                   used == &app ? "the commands" : "the options");
      return 1;
    }
  }

  if (argc <= 1) {  // no subcommand: the usage
    std::printf("%s", app.help().c_str());
    return 0;
  }
  bvhLayout = bvhText == "fast" ? Scene::BvhLayout::Fast : bvhText == "compact" ? Scene::BvhLayout::Compact : Scene::BvhLayout::Auto;
  installInterruptHandlers();  // an interrupt ends the process at once until the work can stop cleanly
  try {
    if (*run) {
      if (experiment.threads < -1) throw Error("--threads: must be ≥ 0");
      if (!onlyRun.empty()) {
        int runIndex = 0;
        size_t colon = onlyRun.find(':');
        try {
          if (colon == std::string::npos) throw std::invalid_argument("no colon");
          runIndex = std::stoi(onlyRun.substr(0, colon));
          experiment.onlySeed = std::stoull(onlyRun.substr(colon + 1));
        } catch (const std::exception&) {
          runIndex = 0;
        }
        if (runIndex < 1) throw Error("--only: expected RUN:SEED (a run number from 1, a seed), got '" + onlyRun + "'");
        experiment.onlyRun = runIndex;
        if (experiment.referenceOnly) throw Error("--only and --reference-only: one or the other");
      }
      return runExperiment(experimentPath, experiment);
    }
    if (*render) {
      if (widthOpt->count() && options.width < 1) throw Error("--width: must be at least 1 pixel, got " + std::to_string(options.width));
      if (heightOpt->count() && options.height < 1)
        throw Error("--height: must be at least 1 pixel, got " + std::to_string(options.height));
      if (timeOpt->count() && (!(options.timeLimit > 0) || !std::isfinite(options.timeLimit)))
        throw Error("--time: must be a number of seconds above 0, got " + formatNumber(options.timeLimit));
      if (options.threads < 0) throw Error("--threads: must be ≥ 0");
      if (seed < 0) throw Error("--seed: must be 0 or more, got " + std::to_string(seed));
      options.seed = uint64_t(seed);
      if (!envText.empty()) {
        options.environment = parseEnvironment(envText, "--env");
        options.environment.rotation = envRotate;
        options.environment.scale = envScale;
        if (!std::isfinite(envRotate)) throw Error("--env-rotate: must be a finite angle in degrees");
        if (!(envScale >= 0) || !std::isfinite(envScale)) throw Error("--env-scale: must be a finite number >= 0");
      } else if (*envRotateOpt || *envScaleOpt) {
        throw Error(std::string(*envRotateOpt ? "--env-rotate" : "--env-scale") + ": needs --env");
      }
      CameraView view;
      if (!lookFrom.empty() || !lookAt.empty()) {
        if (lookFrom.empty() || lookAt.empty()) throw Error(lookFrom.empty() ? "--look-at: needs --look-from" : "--look-from: needs --look-at");
        const std::vector<float> f = parseNumbers("--look-from", lookFrom, 3, "X,Y,Z"), a = parseNumbers("--look-at", lookAt, 3, "X,Y,Z");
        view.kind = CameraView::Kind::LookAt;
        view.from = Vec3(f[0], f[1], f[2]), view.at = Vec3(a[0], a[1], a[2]);
        if (!upText.empty()) {
          const std::vector<float> u = parseNumbers("--up", upText, 3, "X,Y,Z");
          view.up = Vec3(u[0], u[1], u[2]);
        }
      } else if (!upText.empty()) {
        throw Error("--up: only with --look-from and --look-at");
      }
      if (!orbitText.empty()) {
        if (view.kind == CameraView::Kind::LookAt) throw Error("--orbit: not with --look-from (one view or the other)");
        const std::vector<float> o = parseNumbers("--orbit", orbitText, 2, "AZ,EL");
        view.kind = CameraView::Kind::Orbit;
        view.azimuth = o[0], view.elevation = o[1];
      }
      if (fovOpt->count()) {
        if (!(fov > 0)) throw Error("--fov: the vertical field of view must be between 0 and 180 degrees, got " + formatNumber(fov));
        view.fov = fov;
      }
      if (view.kind != CameraView::Kind::File && options.camera >= 0)
        throw Error(std::string("--camera: not with ") + (view.kind == CameraView::Kind::Orbit ? "--orbit" : "--look-from") +
                    " (one view or the other)");
      checkCameraView(view);
      options.view = view;
      if (!findIntegrator(integratorName))
        throw Error("--integrator: unknown integrator '" + integratorName + "' (" + integratorList() + ")");
      RunSettings settings = RunSettings::of(integratorName);
      const IntegratorEntry& entry = settings.entry();
      auto takes = [&] {
        std::string s;
        for (auto& p : entry.params) s += (s.empty() ? "" : ", ") + p.flag();
        return s;
      };
      auto setParam = [&](const std::string& name, const std::string& flag, const std::string& text) {
        if (!settings.params.has(name))
          throw Error(flag + ": is not a parameter of integrator " + integratorName + " (it takes: " + takes() + ")");
        try {
          settings.params.setText(name, text);
        } catch (const Error& e) {
          throw Error(flag + ": " + e.what());
        }
      };
      bool budgetGiven = false;
      for (auto& [name, opt] : paramOpts)
        if (opt->count()) {
          setParam(name, opt->get_name(), paramText[name]);
          budgetGiven = budgetGiven || (entry.budgetParam() && entry.budgetParam()->name == name);
        }
      if (aov == "nan") {
        // Counted per pixel sample: the camera-side integrators' loop (renderPixels).
        if (entry.family != IntegratorFamily::Pixel)
          throw Error("--aov nan: only with " + integratorsOfFamily(IntegratorFamily::Pixel));
        options.nanAov = true;
      } else if (!aov.empty()) {
        setParam("aov", "--aov", aov);
      }
      const bool passes = settings.budgetUnit() == "passes";
      if (checkpoints && !passes) {
        std::string counted;
        for (const IntegratorEntry* e : integrators())
          if (e->budgetParam() && e->budgetParam()->name == "passes") counted += (counted.empty() ? "" : ", ") + e->name;
        throw Error("--checkpoints: only with " + counted);
      }
      if (!sampleRange.empty() || !passRange.empty()) {
        const bool samples = !sampleRange.empty();
        const std::string flag = samples ? "--sample-range" : "--pass-range", unit = samples ? "spp" : "passes";
        if (!sampleRange.empty() && !passRange.empty()) throw Error("--sample-range and --pass-range: one or the other");
        if (entry.sliceUnit != unit) throw Error(flag + ": only with " + integratorsSlicedBy(unit));
        parseRange(flag, samples ? sampleRange : passRange, &options.rangeBegin, &options.rangeEnd, &options.rangeStep);
        if (timeOpt->count()) throw Error(flag + ": a slice is a number of " + unit + ", not a time (no --time)");
        if (checkpoints) throw Error(flag + ": no --checkpoints (a slice's are not the full render's)");
        if (options.nanAov) throw Error(flag + ": not with --aov nan");
        const ParamSpec* budgetSpec = entry.budgetParam();
        if (budgetSpec && budgetGiven && options.rangeEnd > settings.params.integer(budgetSpec->name))
          throw Error(flag + ": " + std::to_string(options.rangeBegin) + ":" + std::to_string(options.rangeEnd) +
                      " reaches past " + budgetSpec->flag() + " " + std::to_string(settings.params.integer(budgetSpec->name)));
        for (const std::string& o : outputs)
          if (fs::path(o).extension() != ".exr") throw Error(flag + ": " + o + ": a slice is written as .exr (its exact sums)");
      }
      // --time alone: as many samples or passes as fit.
      if (options.timeLimit > 0 && !budgetGiven && entry.budgetParam()) settings.params.unset(entry.budgetParam()->name);
      options.progress = !quiet;
      settings.image = options;
      display = parseExposure(exposureText);
      // A debug image (--aov) shows its values as they are unless an exposure is asked for.
      if (!exposureOpt->count() && !aov.empty()) display.autoExposure = false;
      try {
        display.curve = parseToneCurve(toneCurve);
      } catch (const Error& e) {
        throw Error(std::string("--tonemap: ") + e.what());
      }
      bool png = false;
      for (const std::string& o : outputs) png = png || fs::path(o).extension() == ".png";
      std::string notice;  // said once the scene has loaded (an error before it is the only line)
      if (!png && (exposureOpt->count() || tonemapOpt->count()))
        notice = std::string(exposureOpt->count() ? "--exposure" : "--tonemap") +
                 " applies to PNG output only; the EXR stays linear (add -o NAME.png, or develop the EXR later with "
                 "photonlab tonemap)";
      return cmdRender(scenePath, outputs, settings, checkpoints, quiet, display, notice);
    }
    if (*info) return cmdInfo(infoScene, infoUnits);
    if (*compare) return cmdCompare(imagePath, referencePath);
    if (*tonemap) return cmdTonemap(tonemapInput, tonemapOutput, tonemapExposure, tonemapCurve);
    if (*merge) return cmdMerge(mergeParts, mergeOutput, mergePartial);
    if (*bench && !benchLoad.empty()) return runLoadBench(benchLoad, benchRepeats, bvhLayout);
    if (*bench) return runBench(benchScene, benchGlassScene, benchThreads, benchSpp);
    if (*referenceCmd) {
      std::printf("%s", referencePage(referenceName, app).c_str());
      return 0;
    }
    if (*integratorsCmd) {
      if (markdown) {
        std::printf("%s", integratorsMarkdown().c_str());
        return 0;
      }
      for (const IntegratorEntry* e : integrators()) {
        std::printf("%s: %s\n", e->name.c_str(), e->summary.c_str());
        for (const ParamSpec& p : e->params)
          std::printf("  %-20s %-28s %s (default %s; %s)\n", p.flag().c_str(), ("TOML " + p.name).c_str(), p.doc.c_str(),
                      p.defaultValue.empty() ? p.defaultDoc.c_str() : p.defaultValue.c_str(), p.range().c_str());
      }
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "photonlab: %s\n", e.what());
    return 1;
  }
  return 0;
}
