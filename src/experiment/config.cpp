#include "experiment/config.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <toml++/toml.h>

namespace pl {
namespace fs = std::filesystem;

RunSettings RunSettings::of(const std::string& name) {
  RunSettings s;
  s.integrator = name;
  s.params = integratorEntry(name).defaults();
  return s;
}

RenderOptions RunSettings::renderOptions() const {
  RenderOptions o = image;
  if (params.has("spp")) o.spp = int(params.integer("spp"));  // unset (time alone): 0, unlimited
  return o;
}

std::string RunSettings::budgetUnit() const {
  const ParamSpec* b = entry().budgetParam();
  return b ? b->name : "spp";
}

const std::vector<ConfigKey>& experimentKeys() {
  static const std::vector<ConfigKey> keys = {
      {"", "name", "string", "The results folder's name, `results/<name>/` (letters, digits, `-`, `_`, `.`). Required."},
      {"", "description", "string", "One line shown in the report."},
      {"", "scene", "string", "The glTF file (`.gltf` or `.glb`), relative to the config. Required."},
      {"", "units", "string", "How the file's light values are read: `radiometric` or `photometric`, as `--units` (default: what the file says)."},
      {"", "env", "number, [r, g, b] or string", "A sky for every run and the reference, as `--env`: a radiance, \"overcast\", or a map file relative to the config."},
      {"", "env_rotate", "number", "Degrees the `env` map turns about +Y, as `--env-rotate` (needs `env`)."},
      {"", "env_scale", "number", "Factor on the `env` radiance, as `--env-scale` (needs `env`)."},
      {"", "width", "integer", "Image width in pixels, 1 to 16384 (default 512, or from `height` and the camera's aspect)."},
      {"", "height", "integer", "Image height in pixels, 1 to 16384 (default: from the camera's aspect ratio)."},
      {"", "seed", "integer", "The one seed every run renders with (default 1); or `seeds`."},
      {"", "seeds", "array of integers", "Every run renders once per seed (at most 1000, distinct); or `seed`."},
      {"", "threads", "integer", "Worker threads, 0 = all cores (default 0); `photonlab run --threads` overrides it."},
      {"", "inset", "[x, y, width, height]", "The zoomed region of the report's comparison figure, in pixels."},
      {"", "exposure", "number", "Exposure in EV of the PNGs and figures, -64 to 64 (default 0); EXR stays linear."},
      {"", "tonemap", "string", "Tone curve of the PNGs and figures: `clamp` (default) or `aces`."},
      {"", "baseline", "string", "The run (its label) the report's speed-ups are relative to (default: the first run)."},
      {"", "target_relmse", "number", "The report's \"time to reach\" target (default: the baseline's final relMSE)."},
      {"", "reference", "table", "`[reference]`: how the reference is made (keys below). Required."},
      {"", "run", "array of tables", "`[[run]]`: one table per way of rendering the scene (keys below). At least one."},
      {"", "provenance", "table", "Written by `photonlab run` into the results' `experiment.toml` (revision, machine); ignored on input."},
      {"reference", "file", "string", "An existing image to use as the reference, relative to the config; then no other key."},
      {"reference", "integrator", "string", "The integrator that renders the reference (with its parameters, `time` and `spectral`, as a run)."},
      {"reference", "seed", "integer", "The reference's seed (default -1, a stream no run can reach; must not be a run's seed)."},
      {"run", "integrator", "string", "The integrator. Required. Its parameters are keys of the run too (Integrators reference)."},
      {"run", "label", "string", "The run's name in tables and plots, unique (default `<integrator> <n>`)."},
      {"run", "seed", "integer", "This run's one seed, overriding the top level's `seed`/`seeds`."},
      {"run", "seeds", "array of integers", "This run's seeds, overriding the top level's."},
      {"run", "time", "number", "Time budget in seconds, as `--time`; with no `spp`/`passes`, as many as fit."},
      {"run", "spectral", "boolean", "Spectral rendering, as `--spectral` (default false)."},
  };
  return keys;
}

const std::vector<std::string>& RunSettings::commonKeys() {
  static const std::vector<std::string> keys = {"time", "spectral"};
  return keys;
}

namespace {

class Parser {
 public:
  explicit Parser(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& what) const {
    std::string where = path_;
    if (node && node->source().begin.line > 0) where += ":" + std::to_string(node->source().begin.line);
    throw Error(where + ": " + key + ": " + what);
  }
  [[noreturn]] void fail(int line, const std::string& key, const std::string& what) const {
    throw Error(path_ + (line > 0 ? ":" + std::to_string(line) : "") + ": " + key + ": " + what);
  }

  std::string string(const toml::node& n, const std::string& key) const {
    if (!n.is_string()) fail(&n, key, std::string("must be a string, got ") + typeName(n));
    return n.as_string()->get();
  }
  int64_t integer(const toml::node& n, const std::string& key, int64_t lo, int64_t hi) const {
    if (!n.is_integer()) fail(&n, key, std::string("must be an integer, got ") + typeName(n));
    int64_t v = n.as_integer()->get();
    if (v < lo || v > hi) fail(&n, key, "must be from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got " + std::to_string(v));
    return v;
  }
  // A real number in (lo, hi] (or [lo, hi] when closedLow); integers are accepted.
  double number(const toml::node& n, const std::string& key, double lo, double hi, bool closedLow) const {
    double v;
    if (n.is_integer()) v = double(n.as_integer()->get());
    else if (n.is_floating_point()) v = n.as_floating_point()->get();
    else fail(&n, key, std::string("must be a number, got ") + typeName(n));
    bool ok = std::isfinite(v) && (closedLow ? v >= lo : v > lo) && v <= hi;
    if (!ok) {
      std::ostringstream s;
      s << "must be in " << (closedLow ? "[" : "(") << lo << ", " << hi << "], got " << v;
      fail(&n, key, s.str());
    }
    return v;
  }
  // `seed = 1` (one integer) or `seeds = [1, 2, 3]` (a list), as `list` says.
  std::vector<uint64_t> seeds(const toml::node& n, const std::string& key, bool list) const {
    std::vector<uint64_t> out;
    if (!list) {
      out.push_back(uint64_t(integer(n, key, 0, INT64_MAX)));
      return out;
    }
    const toml::array* a = n.as_array();
    if (!a) fail(&n, key, std::string("must be an array of integers, got ") + typeName(n));
    if (a->empty()) fail(&n, key, "must list at least one seed");
    if (a->size() > 1000) fail(&n, key, "at most 1000 seeds");
    std::set<uint64_t> seen;
    for (auto& e : *a) {
      uint64_t s = uint64_t(integer(e, key, 0, INT64_MAX));
      if (!seen.insert(s).second) fail(&e, key, "seed " + std::to_string(s) + " is listed twice");
      out.push_back(s);
    }
    return out;
  }

  static const char* typeName(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a number";
      case toml::node_type::boolean: return "a boolean";
      case toml::node_type::array: return "an array";
      case toml::node_type::table: return "a table";
      default: return "a date or time";
    }
  }

  // `integrator`, then every other key of a run (or of the reference) into `s`.
  // `prefix` names the table in messages ("run[2]", "reference"). A key that does not apply is
  // an error: `alpha = 0.5` on a path-traced run is a mistake the user wants to hear about, not a
  // silent no-op.
  void runSettings(const toml::table& t, const std::string& prefix, const std::set<std::string>& alsoAllowed, RunSettings* s) const {
    const toml::node* in = t.get("integrator");
    if (!in) fail(int(t.source().begin.line), prefix, "needs an integrator (" + integratorList() + ")");
    std::string integrator = string(*in, prefix + ".integrator");
    if (!findIntegrator(integrator))
      fail(in, prefix + ".integrator", "unknown integrator '" + integrator + "' (" + integratorList() + ")");
    *s = RunSettings::of(integrator);
    const IntegratorEntry& entry = s->entry();
    const ParamSpec* budget = entry.budgetParam();
    bool hasBudget = false, hasTime = false;

    for (auto&& [k, node] : t) {
      const std::string key(k.str()), name = prefix + "." + key;
      if (key == "integrator" || alsoAllowed.count(key)) continue;
      if (key == "spectral") {
        if (!node.is_boolean()) fail(&node, name, std::string("must be true or false, got ") + typeName(node));
        s->image.spectral = node.as_boolean()->get();
        continue;
      }
      if (key == "time") {
        hasTime = true;
        s->image.timeLimit = number(node, name, 0.0, 1e7, false);
        continue;
      }
      const ParamSpec* spec = s->params.spec(key);
      if (!spec) {
        if (integratorsTaking(key).empty()) fail(&node, name, "unknown key (known: " + knownKeys(entry, alsoAllowed) + ")");
        fail(&node, name, "is not a parameter of integrator " + s->integrator + " (it takes: " + knownKeys(entry, alsoAllowed) + ")");
      }
      if (spec->type == ParamType::Integer && !node.is_integer())
        fail(&node, name, std::string("must be an integer, got ") + typeName(node));
      if (spec->type == ParamType::Real && !node.is_integer() && !node.is_floating_point())
        fail(&node, name, std::string("must be a number, got ") + typeName(node));
      if (spec->type == ParamType::Choice && !node.is_string())
        fail(&node, name, std::string("must be a string, got ") + typeName(node));
      try {
        if (spec->type == ParamType::Choice) s->params.setChoice(key, node.as_string()->get());
        else if (node.is_integer()) s->params.setNumber(key, double(node.as_integer()->get()));
        else s->params.setNumber(key, node.as_floating_point()->get());
      } catch (const Error& e) {
        fail(&node, name, e.what());
      }
      if (budget && key == budget->name) hasBudget = true;
    }
    // A time budget alone means: as many samples or passes as fit.
    if (hasTime && !hasBudget && budget) s->params.unset(budget->name);
  }

  static std::string knownKeys(const IntegratorEntry& entry, const std::set<std::string>& also) {
    std::string s = "integrator";
    for (auto& a : also) s += ", " + a;
    for (auto& k : RunSettings::commonKeys()) s += ", " + k;
    for (auto& p : entry.params) s += ", " + p.name;
    return s;
  }

  // Relative to the config's folder (the working directory for "exp.toml"). Paths the file
  // system cannot represent (a NUL byte) are errors, not exceptions from <filesystem>.
  std::string resolvePath(const toml::node& n, const std::string& key) const {
    std::string p = string(n, key);
    if (p.empty() || p.find('\0') != std::string::npos) fail(&n, key, "not a usable file name");
    std::error_code ec;
    fs::path folder = fs::path(path_).parent_path();
    fs::path path(p);
    if (path.is_relative()) path = fs::absolute(folder.empty() ? fs::path(".") : folder, ec) / path;
    if (ec) fail(&n, key, "cannot resolve '" + p + "': " + ec.message());
    return path.lexically_normal().string();
  }
  static bool isFile(const std::string& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec);
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

std::vector<RunSettings*> allSettings(ExperimentConfig& c) {
  std::vector<RunSettings*> all{&c.reference.settings};
  for (auto& r : c.runs) all.push_back(&r.settings);
  return all;
}

ExperimentConfig parseExperiment(std::string_view text, const std::string& path) {
  Parser p(path);
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw Error(path + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }

  ExperimentConfig c;
  c.path = path;
  std::vector<uint64_t> seeds{1};
  const toml::node* referenceNode = nullptr;
  const toml::node* baselineNode = nullptr;
  const toml::node* runNode = nullptr;
  bool hasSeed = false;
  EnvironmentSpec environment;
  std::string units;
  const toml::node *envRotate = nullptr, *envScale = nullptr;
  for (auto&& [k, node] : root) {
    const std::string key(k.str());
    if (key == "name") {
      c.name = p.string(node, key);
      bool ok = !c.name.empty() && c.name.size() <= 100 && c.name[0] != '.';
      for (char ch : c.name) ok = ok && (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.');
      if (!ok) p.fail(&node, key, "must be a folder name: letters, digits, '-', '_', '.' (got '" + c.name + "')");
    } else if (key == "description") {
      c.description = p.string(node, key);
    } else if (key == "scene") {
      c.scene = p.resolvePath(node, key);
      if (!Parser::isFile(c.scene)) p.fail(&node, key, "no such file: " + c.scene);
    } else if (key == "width") {
      c.width = int(p.integer(node, key, 1, 16384));
    } else if (key == "height") {
      c.height = int(p.integer(node, key, 1, 16384));
    } else if (key == "threads") {
      c.threads = int(p.integer(node, key, 0, 1024));
    } else if (key == "seed" || key == "seeds") {
      if (hasSeed) p.fail(&node, key, "give either seed or seeds, not both");
      hasSeed = true;
      seeds = p.seeds(node, key, key == "seeds");
    } else if (key == "inset") {
      const toml::array* a = node.as_array();
      if (!a || a->size() != 4) p.fail(&node, key, "must be [x, y, width, height] in pixels");
      std::array<int, 4> v{};
      for (size_t i = 0; i < 4; ++i) v[i] = int(p.integer((*a)[i], key, i < 2 ? 0 : 1, 16384));
      c.inset = v;
    } else if (key == "exposure") {
      c.display.exposure = p.number(node, key, -64, 64, true);
    } else if (key == "tonemap") {
      std::string curve = p.string(node, key);
      try {
        c.display.curve = parseToneCurve(curve);
      } catch (const Error& e) {
        p.fail(&node, key, e.what());
      }
    } else if (key == "baseline") {
      c.baseline = p.string(node, key);
      baselineNode = &node;
    } else if (key == "target_relmse") {
      c.targetRelmse = p.number(node, key, 0.0, 1e9, false);
    } else if (key == "reference") {
      referenceNode = &node;
    } else if (key == "run") {
      runNode = &node;
    } else if (key == "env") {
      // As --env: a radiance (one number, or [r, g, b]) or, as text, what --env takes (a map file
      // relative to this config).
      if (node.is_string()) {
        try {
          environment = parseEnvironment(p.string(node, key), key);
        } catch (const Error& e) {  // "env: what is wrong", said with the line
          p.fail(&node, key, std::string(e.what()).substr(key.size() + 2));
        }
        if (!environment.map.empty()) environment.map = p.resolvePath(node, key);
      } else {
        const toml::array* a = node.as_array();
        if (a && a->size() != 3) p.fail(&node, key, "must be one number, [r, g, b], or text as --env takes");
        auto channel = [&](size_t i) { return float(p.number(a ? (*a)[i] : node, key, 0, 1e30, true)); };
        environment.enabled = true;
        environment.radiance = a ? Spectrum(channel(0), channel(1), channel(2)) : Spectrum(channel(0));
      }
    } else if (key == "units") {
      units = p.string(node, key);
      if (units != "radiometric" && units != "photometric") p.fail(&node, key, "must be \"radiometric\" or \"photometric\"");
    } else if (key == "env_rotate") {
      environment.rotation = float(p.number(node, key, -1e6, 1e6, true));
      envRotate = &node;
    } else if (key == "env_scale") {
      environment.scale = float(p.number(node, key, 0, 1e30, true));
      envScale = &node;
    } else if (key == "provenance") {
      // Written by `photonlab run` into experiment.toml, which can be run again as it is.
      if (!node.is_table()) p.fail(&node, key, "must be a table");
    } else {
      std::string known;
      for (const ConfigKey& k : experimentKeys())
        if (k.table.empty())
          known += (known.empty() ? "" : ", ") + (k.key == "run" ? "[[run]]" : k.type == "table" ? "[" + k.key + "]" : k.key);
      p.fail(&node, key, "unknown key (known: " + known + ")");
    }
  }
  if (!environment.enabled && (envRotate || envScale))
    p.fail(envRotate ? envRotate : envScale, envRotate ? "env_rotate" : "env_scale", "needs env");
  if (c.name.empty()) p.fail(1, "name", "missing (the results folder name)");
  if (c.scene.empty()) p.fail(1, "scene", "missing (a .gltf or .glb file, relative to this config)");
  if (c.width == 0) c.width = c.height == 0 ? 512 : 0;  // height alone: width from the aspect ratio
  if (c.inset && c.height > 0 && ((*c.inset)[0] + (*c.inset)[2] > c.width || (*c.inset)[1] + (*c.inset)[3] > c.height))
    p.fail(1, "inset", "region lies outside the image");

  // [reference]
  if (!referenceNode) p.fail(1, "reference", "missing: a [reference] table with an integrator or a file");
  const toml::table* ref = referenceNode->as_table();
  if (!ref) p.fail(referenceNode, "reference", "must be a table ([reference])");
  if (const toml::node* f = ref->get("file")) {
    if (ref->size() != 1) p.fail(f, "reference.file", "a reference file takes no other keys");
    c.reference.file = p.resolvePath(*f, "reference.file");
    if (!Parser::isFile(c.reference.file)) p.fail(f, "reference.file", "no such file: " + c.reference.file);
  } else {
    p.runSettings(*ref, "reference", {"seed"}, &c.reference.settings);
  }
  const toml::node* referenceSeed = ref->get("seed");
  c.reference.settings.image.seed =
      referenceSeed ? uint64_t(p.integer(*referenceSeed, "reference.seed", INT64_MIN, INT64_MAX)) : kReferenceSeed;

  // [[run]]
  if (!runNode) p.fail(1, "run", "missing: at least one [[run]] table");
  const toml::array* runs = runNode->as_array();
  if (!runs || runs->empty() || !runs->is_array_of_tables()) p.fail(runNode, "run", "must be one or more [[run]] tables");
  std::set<std::string> labels;
  for (size_t i = 0; i < runs->size(); ++i) {
    const toml::table& t = *(*runs)[i].as_table();
    const std::string prefix = "run[" + std::to_string(i + 1) + "]";
    RunConfig r;
    r.line = int(t.source().begin.line);
    p.runSettings(t, prefix, {"label", "seed", "seeds"}, &r.settings);
    r.seeds = seeds;
    bool runSeed = false;
    for (auto&& [k, node] : t) {
      const std::string key(k.str());
      if (key == "label") r.label = p.string(node, prefix + ".label");
      if (key == "seed" || key == "seeds") {
        if (runSeed) p.fail(&node, prefix + "." + key, "give either seed or seeds, not both");
        runSeed = true;
        r.seeds = p.seeds(node, prefix + "." + key, key == "seeds");
      }
    }
    if (r.label.empty()) r.label = r.settings.integrator + " " + std::to_string(i + 1);
    if (r.label.size() > 200) p.fail(r.line, prefix + ".label", "longer than 200 characters");
    if (!labels.insert(r.label).second) p.fail(r.line, prefix + ".label", "'" + r.label + "' is used by another run");
    c.runs.push_back(std::move(r));
  }
  if (!c.baseline.empty()) {
    bool found = false;
    for (auto& r : c.runs) found = found || r.label == c.baseline;
    if (!found) p.fail(baselineNode, "baseline", "no run is labelled '" + c.baseline + "'");
  }
  // An explicit reference seed must not be a run's: the run would be scored against an image
  // made from its own random numbers.
  if (referenceSeed && int64_t(c.reference.settings.image.seed) >= 0)
    for (size_t i = 0; i < c.runs.size(); ++i)
      for (uint64_t s : c.runs[i].seeds)
        if (s == c.reference.settings.image.seed)
          p.fail(referenceSeed, "reference.seed",
                 "seed " + std::to_string(s) + " is also a seed of run[" + std::to_string(i + 1) + "] ('" + c.runs[i].label +
                     "'): the reference must not share random numbers with a run (leave it out: the reference then "
                     "draws from seed -1, which no run can use)");
  for (RunSettings* s : allSettings(c)) {
    s->image.width = c.width;
    s->image.height = c.height;
    s->image.threads = c.threads;
    s->image.environment = environment;
    s->image.units = units;
  }
  return c;
}

ExperimentConfig loadExperiment(const std::string& path) {
  if (!Parser::isFile(path)) throw Error(path + ": no such experiment file");
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in && !in.eof()) throw Error(path + ": cannot read");
  return parseExperiment(ss.str(), path);
}

namespace {

void addSettings(toml::table& t, const RunSettings& s) {
  t.insert_or_assign("integrator", s.integrator);
  if (s.image.timeLimit > 0) t.insert_or_assign("time", s.image.timeLimit);
  if (s.image.spectral) t.insert_or_assign("spectral", true);
  // Every parameter that has a value, typed as declared (an unset budget: unlimited; an unset
  // radius: resolved from the scene before this is written, or the method's own default).
  for (const ParamSpec& p : s.params.specs()) {
    if (!s.params.isSet(p.name)) continue;
    if (p.type == ParamType::Choice) t.insert_or_assign(p.name, s.params.choice(p.name));
    else if (p.type == ParamType::Integer) t.insert_or_assign(p.name, s.params.integer(p.name));
    else t.insert_or_assign(p.name, s.params.real(p.name));
  }
}

}  // namespace

std::string resolvedConfigToml(const ExperimentConfig& c, const std::vector<std::pair<std::string, std::string>>& provenance) {
  toml::table root;
  root.insert("name", c.name);
  if (!c.description.empty()) root.insert("description", c.description);
  root.insert("scene", c.scene);
  if (!c.runs.front().settings.image.units.empty()) root.insert("units", c.runs.front().settings.image.units);
  const EnvironmentSpec& env = c.runs.front().settings.image.environment;
  if (env.enabled) {
    if (env.map.empty()) root.insert("env", toml::array{env.radiance.r, env.radiance.g, env.radiance.b});
    else root.insert("env", env.map);
    root.insert("env_rotate", env.rotation);
    root.insert("env_scale", env.scale);
  }
  if (c.width > 0) root.insert("width", c.width);
  if (c.height > 0) root.insert("height", c.height);
  root.insert("threads", c.threads);
  if (c.inset) root.insert("inset", toml::array{(*c.inset)[0], (*c.inset)[1], (*c.inset)[2], (*c.inset)[3]});
  root.insert("exposure", c.display.exposure);
  root.insert("tonemap", toneCurveName(c.display.curve));
  root.insert("baseline", c.baseline.empty() ? c.runs.front().label : c.baseline);
  if (c.targetRelmse > 0) root.insert("target_relmse", c.targetRelmse);
  toml::table ref;
  if (!c.reference.file.empty()) {
    ref.insert("file", c.reference.file);
  } else {
    addSettings(ref, c.reference.settings);
    ref.insert("seed", int64_t(c.reference.settings.image.seed));
  }
  root.insert("reference", std::move(ref));
  toml::array runs;
  for (auto& r : c.runs) {
    toml::table t;
    t.insert("label", r.label);
    addSettings(t, r.settings);
    toml::array seeds;
    for (auto s : r.seeds) seeds.push_back(int64_t(s));
    t.insert("seeds", std::move(seeds));
    runs.push_back(std::move(t));
  }
  root.insert("run", std::move(runs));
  toml::table prov;
  for (auto& [k, v] : provenance) prov.insert(k, v);
  root.insert("provenance", std::move(prov));
  std::ostringstream out;
  out << "# Written by photonlab run: the experiment as rendered, every default filled in.\n" << root << "\n";
  return out.str();
}

std::string settingsFingerprint(const RunSettings& s) {
  toml::table t;
  addSettings(t, s);
  t.insert_or_assign("width", s.image.width);
  t.insert_or_assign("height", s.image.height);
  t.insert_or_assign("seed", int64_t(s.image.seed));
  if (s.image.environment.enabled) t.insert_or_assign("environment", s.image.environment.describe());
  if (!s.image.units.empty()) t.insert_or_assign("units", s.image.units);
  std::ostringstream out;
  out << t;
  return out.str();
}

}  // namespace pl
