// The one list of integrators. Each built-in declares itself in its own .cpp file as a function
// returning its entry, and integrators/builtins.cpp registers them all by name:
//
//   IntegratorEntry pathEntry() {
//     return IntegratorEntry("path", "unidirectional path tracing ...", IntegratorFamily::Pixel, "spp",
//         {params::spp(), params::maxDepth()},
//         [](const ParamSet& p, const RenderOptions&) { return std::make_unique<PathIntegrator>(...); });
//   }
//
// Everything else (the CLI's flags and --help, the TOML keys and their validation, the
// reference-cache fingerprint, the images' metadata, `photonlab integrators`, the documentation's
// reference page) reads these entries. Another integrator (a test's, a plugin's) registers itself
// with a static IntegratorRegistration in its own file, linked directly.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/integrator.h"
#include "integrators/params.h"

namespace pl {

// How an integrator is driven (render/integrator.h): by the shared per-pixel loop
// (PixelIntegrator), by passes of eye and photon paths (PassIntegrator), by the light-path loop
// (LightPathIntegrator), or by a render() of its own.
enum class IntegratorFamily { Pixel, Pass, LightPaths, Own };
const char* familyName(IntegratorFamily family);

// What an integrator's image converges to; the contract's closed-form tests (tests/
// test_contract.cpp) hold every registered integrator to it.
enum class Converges {
  kRadiance,        // the rendering equation's solution: every path up to max_depth
  kDirectLighting,  // emission plus one bounce of light at diffuse surfaces (specular chains aside)
  kOther,           // not radiance (a test's ambient occlusion): no light-transport closed form applies
};
const char* convergesName(Converges converges);

// A set of LightTypes (lights/light.h), one bit each.
using LightTypes = uint32_t;
constexpr LightTypes lightTypeBit(LightType t) { return LightTypes(1) << unsigned(t); }
constexpr LightTypes kEveryLightType = lightTypeBit(LightType::kDeltaPosition) | lightTypeBit(LightType::kDeltaDirection) |
                                       lightTypeBit(LightType::kArea) | lightTypeBit(LightType::kInfinite);

struct IntegratorEntry {
  using Factory = std::function<std::unique_ptr<Integrator>(const ParamSet&, const RenderOptions&)>;
  using Resolve = std::function<std::string(const Scene&, int width, int height, ParamSet&)>;
  IntegratorEntry(std::string name, std::string summary, IntegratorFamily family, const char* sliceUnit,
                  std::vector<ParamSpec> params, Factory make, Resolve resolve = {})
      : name(std::move(name)), summary(std::move(summary)), family(family), sliceUnit(sliceUnit ? sliceUnit : ""),
        params(std::move(params)), make(std::move(make)), resolve(std::move(resolve)) {}

  std::string name;
  std::string summary;  // one line
  IntegratorFamily family;
  // What `--sample-range` ("spp") or `--pass-range` ("passes") slices a render of it by, so
  // that slices merge into the whole render bit for bit (RenderOptions::rangeBegin/End): "spp"
  // where samples or iterations are independent estimates averaged with equal weights,
  // "passes" for PPPM's independent passes; "" where slices would not add up (SPPM's per-pixel
  // radii depend on every earlier pass; guiding's iterations on the ones before).
  std::string sliceUnit;
  std::vector<ParamSpec> params;
  Factory make;
  // Optional: fills scene-dependent defaults into the parameters before rendering (so that the
  // metadata and the resolved config say what was used) and says what it chose, in words, for
  // the summary line ("" when there is nothing to say).
  Resolve resolve;

  // What its image converges to, and the kinds of light it carries (a scene with another kind
  // is refused or its light is missing); set after construction where they differ.
  Converges converges = Converges::kRadiance;
  LightTypes carries = kEveryLightType;
  // The integer parameters that, doubled together, lower its error (empty: its budget
  // parameter): e.g. the photon count beside the samples of a fixed photon map, the patch count
  // of radiosity. The closed-form tests raise them until the estimate can be judged.
  std::vector<std::string> refinement;

  // The parameter that is the render's budget unit ("spp" or "passes"), or nullptr.
  const ParamSpec* budgetParam() const;
  // A parameter set holding every default.
  ParamSet defaults() const { return ParamSet(&params); }
};

// Adds an entry to the list; throws Error when the name is taken or the declaration is
// inconsistent (two parameters of one name, a default outside its range, two budgets).
class IntegratorRegistration {
 public:
  explicit IntegratorRegistration(IntegratorEntry entry);
};

// The integrators sliced by `unit` ("spp" or "passes"), as a list for messages.
std::string integratorsSlicedBy(const std::string& unit);
// The integrators of one family, as a list for messages.
std::string integratorsOfFamily(IntegratorFamily family);

// Sorted by name.
std::vector<const IntegratorEntry*> integrators();
// nullptr when unknown.
const IntegratorEntry* findIntegrator(const std::string& name);
// Throws Error("unknown integrator 'x' (a, b, ...)").
const IntegratorEntry& integratorEntry(const std::string& name);
std::vector<std::string> integratorNames();
std::string integratorList();  // "direct, light, path, ..."
// The integrators that declare parameter `param`, as a list for messages.
std::string integratorsTaking(const std::string& param);

// Makes the named integrator from its parameters (the defaults when `params` is empty).
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const ParamSet& params, const RenderOptions& image);
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const RenderOptions& image = {});

// Markdown: one table per integrator (parameter, type, default, range, meaning), the documentation's
// Integrators reference (docs/pages/reference/integrators.md); a test checks the page against it.
std::string integratorsMarkdown();
std::string integratorMarkdown(const IntegratorEntry& entry);  // one of them
// Text for a Markdown page: angle brackets outside `code spans` escaped, so that a placeholder
// such as OUT.s<S>t<T>.ext is not read as an HTML tag (the documentation's generated pages).
std::string markdownText(const std::string& text);

}  // namespace pl
