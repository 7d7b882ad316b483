#include "integrators/params.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace pl {

std::string ParamSpec::flag() const {
  std::string f = "--" + name;
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

std::string ParamSpec::range() const {
  if (type == ParamType::Choice) {
    std::string s;
    for (auto& c : choices) s += (s.empty() ? "" : ", ") + c;
    return s;
  }
  std::ostringstream s;
  if (type == ParamType::Integer) s << "from " << int64_t(lo) << " to " << int64_t(hi);
  else s << "in " << (openLow ? "(" : "[") << lo << ", " << hi << "]";
  return s.str();
}

ParamSet::ParamSet(const std::vector<ParamSpec>* specs) : specs_(specs) {
  for (const ParamSpec& s : *specs) {
    if (s.defaultValue.empty()) continue;
    if (s.type == ParamType::Choice) values_[s.name].text = s.defaultValue;
    else values_[s.name].number = std::strtod(s.defaultValue.c_str(), nullptr);
  }
}

const ParamSpec* ParamSet::spec(const std::string& name) const {
  if (!specs_) return nullptr;
  for (const ParamSpec& s : *specs_)
    if (s.name == name) return &s;
  return nullptr;
}

void ParamSet::check(const ParamSpec& s, double v) const {
  if (s.type == ParamType::Integer) {
    if (!(v >= s.lo && v <= s.hi) || v != std::floor(v)) {
      std::ostringstream m;
      m << "must be " << s.range() << ", got " << (std::isfinite(v) && v == std::floor(v) ? std::to_string(int64_t(v)) : formatNumber(v));
      throw Error(m.str());
    }
    return;
  }
  bool ok = std::isfinite(v) && (s.openLow ? v > s.lo : v >= s.lo) && v <= s.hi;
  if (!ok) {
    std::ostringstream m;
    m << "must be " << s.range() << ", got " << v;
    throw Error(m.str());
  }
}

void ParamSet::setNumber(const std::string& name, double v) {
  const ParamSpec& s = declared(name);
  if (s.type == ParamType::Choice) throw Error("must be one of " + s.range());
  check(s, v);
  values_[name].number = v;
}

void ParamSet::setChoice(const std::string& name, const std::string& v) {
  const ParamSpec& s = declared(name);
  if (s.type != ParamType::Choice) throw Error("must be a number");
  for (auto& c : s.choices)
    if (c == v) {
      values_[name].text = v;
      return;
    }
  throw Error("unknown " + name + " '" + v + "' (" + s.range() + ")");
}

void ParamSet::setText(const std::string& name, const std::string& text) {
  const ParamSpec& s = declared(name);
  if (s.type == ParamType::Choice) return setChoice(name, text);
  // The whole text must be one number: "12abc", "" and " 3" are refused.
  char* end = nullptr;
  double v = text.empty() || std::isspace(static_cast<unsigned char>(text[0])) ? NAN : std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size())
    throw Error(std::string(s.type == ParamType::Integer ? "must be an integer" : "must be a number") + ", got '" + text + "'");
  setNumber(name, v);
}

const ParamSpec& ParamSet::declared(const std::string& name) const {
  const ParamSpec* s = spec(name);
  if (!s) {
    std::string names;
    for (const ParamSpec& p : specs()) names += (names.empty() ? "" : ", ") + p.name;
    throw Error("'" + name + "' is not a declared parameter (declared: " + (names.empty() ? "none" : names) + ")");
  }
  return *s;
}

double ParamSet::real(const std::string& name) const {
  declared(name);
  auto it = values_.find(name);
  return it == values_.end() ? 0.0 : it->second.number;
}

std::string ParamSet::choice(const std::string& name) const {
  declared(name);
  auto it = values_.find(name);
  return it == values_.end() ? std::string() : it->second.text;
}

std::string ParamSet::format(const ParamSpec& s) const {
  if (s.type == ParamType::Choice) return choice(s.name);
  if (s.type == ParamType::Integer) return std::to_string(integer(s.name));
  return formatNumber(real(s.name));
}

namespace params {

ParamSpec choice(std::string name, std::string doc, std::string defaultValue, std::vector<std::string> choices) {
  ParamSpec s{std::move(name), ParamType::Choice, std::move(doc), std::move(defaultValue)};
  s.choices = std::move(choices);
  return s;
}

ParamSpec maxDepth() {
  ParamSpec s{"max_depth", ParamType::Integer, "maximum number of bounces (path segments after the camera ray)", "64"};
  s.lo = 0, s.hi = 10000;
  return s;
}

ParamSpec spp() {
  ParamSpec s{"spp", ParamType::Integer, "samples per pixel", "16"};
  s.lo = 1, s.hi = 1 << 24;
  s.budget = true;
  return s;
}

ParamSpec passes() {
  ParamSpec s{"passes", ParamType::Integer, "number of photon passes", "64"};
  s.lo = 1, s.hi = 1 << 24;
  s.budget = true;
  return s;
}

ParamSpec photonsPerPass(const char* defaultValue) {
  ParamSpec s{"photons_per_pass", ParamType::Integer, "photon paths emitted per pass", defaultValue};
  if (!*defaultValue) s.defaultDoc = "the image's pixel count";
  s.lo = 1, s.hi = 4294967295.0;
  return s;
}

ParamSpec alpha() {
  // 2/3 exactly as a double (the shortest text that reads back as it).
  ParamSpec s{"alpha", ParamType::Real, "fraction of new photons kept (radius reduction); 2/3 minimises the MSE",
              "0.6666666666666666"};
  s.defaultDoc = "2/3";
  s.lo = 0, s.hi = 1, s.openLow = true;
  return s;
}

ParamSpec photonTarget() {
  return choice("photon_target",
                "where photons from a sky or the sun start: view: half of them on the disc covering what the camera sees, the rest "
                "on the scene's (flux weighted by the mixture's density: unbiased); scene: all on the scene's disc",
                "view", {"view", "scene"});
}

ParamSpec aimAreaLights() {
  return choice("aim_area_lights",
                "with photon_target view, area lights aim half of their photons at what the camera sees too (flux weighted by the "
                "mixture's density: unbiased): for a close-up under a large emitter, not for light that reaches the view by "
                "bounces",
                "off", {"off", "on"});
}

ParamSpec photonSampling() {
  return choice("photon_sampling",
                "how photon paths are drawn: uniform: independently, by the lights' emission and the BSDFs; adaptive: a Markov "
                "chain over paths that land near a visible point, normalised by the uniform paths' visible fraction "
                "(Hachisuka & Jensen 2011)",
                "uniform", {"uniform", "adaptive"});
}

ParamSpec progressiveRadius() {
  ParamSpec s{"radius", ParamType::Real, "initial gather radius in metres"};
  s.defaultDoc = "5 pixel footprints at the median visible distance";
  s.lo = 0, s.hi = 1e9, s.openLow = true;
  s.metadataKey = "initial_radius";
  return s;
}

ParamSpec sampler(int slots, const std::string& paths, const std::string& over, const char* defaultValue) {
  return choice("sampler",
                "where each " + paths + "'s first " + std::to_string(slots) +
                    " draws (a 1D or 2D sample each" + (paths == "camera path" ? ", the pixel jitter first" : "") +
                    ") come from: independent (a random stream) or sobol (Owen-scrambled Sobol' points over " + over + ")",
                defaultValue, {"independent", "sobol"});
}

}  // namespace params

}  // namespace pl
