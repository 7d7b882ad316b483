// Declared integrator parameters. Each integrator lists what it takes (name, type, default,
// valid range, one line of doc) in its own file (integrators/registry.h); the command line, the
// experiment TOML, the reference-cache fingerprint, the images' metadata and the documentation's reference tables
// are all derived from those declarations, so they cannot disagree.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/common.h"

namespace pl {

enum class ParamType { Integer, Real, Choice };

struct ParamSpec {
  ParamSpec(std::string name, ParamType type, std::string doc, std::string defaultValue = "")
      : name(std::move(name)), type(type), doc(std::move(doc)), defaultValue(std::move(defaultValue)) {}

  std::string name;  // TOML key; on the command line with '-' for '_' (max_depth: --max-depth)
  ParamType type = ParamType::Integer;
  std::string doc;
  // The default as text; empty: "not given", which the integrator resolves itself (said in
  // defaultDoc, e.g. "derived from the scene").
  std::string defaultValue;
  // The default in words for documentation: what an unset value means, or a plainer form of
  // defaultValue ("2/3").
  std::string defaultDoc;
  double lo = 0, hi = 0;
  bool openLow = false;                // the range is (lo, hi] instead of [lo, hi]
  std::vector<std::string> choices;    // ParamType::Choice
  // The render's budget in samples or passes: with a time budget and no value, unlimited.
  bool budget = false;
  // Written to the images' metadata under this key (default: name).
  std::string metadataKey;

  std::string flag() const;  // "--max-depth"
  std::string range() const;  // "from 1 to 16777216", "in (0, 1]", "uniform, cone, ..."
  const std::string& metaKey() const { return metadataKey.empty() ? name : metadataKey; }
};

// A parameter's value: a number for Integer and Real, text for Choice.
struct ParamValue {
  double number = 0;
  std::string text;
};

// The parameters of one integrator: every declared one has a value (its default) or is unset.
class ParamSet {
 public:
  ParamSet() = default;
  explicit ParamSet(const std::vector<ParamSpec>* specs);

  const std::vector<ParamSpec>& specs() const {
    static const std::vector<ParamSpec> none;
    return specs_ ? *specs_ : none;
  }
  const ParamSpec* spec(const std::string& name) const;
  bool has(const std::string& name) const { return spec(name) != nullptr; }
  bool isSet(const std::string& name) const { return values_.count(name) > 0; }

  // Validated against the declaration; throws Error("what") without the key (callers prefix it:
  // "--alpha: ", "FILE:LINE: run[1].alpha: "), with the same words from the CLI and from TOML.
  void setText(const std::string& name, const std::string& text);  // command line
  void setNumber(const std::string& name, double v);               // TOML numbers
  void setChoice(const std::string& name, const std::string& v);   // TOML strings
  void unset(const std::string& name) { values_.erase(name); }
  // For scene-derived defaults (an integrator's resolve step): no validation.
  void resolve(const std::string& name, double v) { values_[declared(name).name].number = v; }

  // Typed reads of a declared parameter; the unset ones read as 0 / "". Reading or setting a
  // name the integrator does not declare throws Error: a typo is never a silent 0.
  double real(const std::string& name) const;
  int64_t integer(const std::string& name) const { return int64_t(real(name)); }
  std::string choice(const std::string& name) const;

  std::string format(const ParamSpec& spec) const;

 private:
  const ParamSpec& declared(const std::string& name) const;  // throws for an undeclared name
  void check(const ParamSpec& s, double v) const;
  const std::vector<ParamSpec>* specs_ = nullptr;
  std::map<std::string, ParamValue> values_;
};

// The declarations several integrators share, written once.
namespace params {
// A Choice parameter: its values, and the one it takes when not given.
ParamSpec choice(std::string name, std::string doc, std::string defaultValue, std::vector<std::string> choices);
ParamSpec maxDepth();
ParamSpec spp();
ParamSpec passes();
ParamSpec photonsPerPass(const char* defaultValue);  // "": the pixel count
ParamSpec alpha();
ParamSpec progressiveRadius();
// --photon-target: where photons from lights at infinity start (photon/photon_tracer.h,
// EmissionTarget): half of them aimed at the region in view, or all over the scene's disc.
ParamSpec photonTarget();
ParamSpec aimAreaLights();
ParamSpec photonSampling();
// --sampler (core/sampler.h): independent, or Sobol' points for the first `slots` draws of each
// path, `paths` and `over` saying which paths and over what their points are indexed;
// `defaultValue` is the integrator's own choice.
ParamSpec sampler(int slots, const std::string& paths, const std::string& over, const char* defaultValue = "independent");
}  // namespace params

}  // namespace pl
