// The one list of integrators. Each registers itself in its own .cpp file:
//
//   static const IntegratorRegistration reg({"path", "unidirectional path tracing ...",
//       {params::spp(), params::maxDepth()},
//       [](const ParamSet& p, const RenderOptions&) { return std::make_unique<PathIntegrator>(...); }});
//
// Everything else (the CLI's flags and --help, the TOML keys and their validation, the
// reference-cache fingerprint, the images' metadata, `photonlab integrators`, the documentation's reference page)
// reads these entries. Adding an integrator is its own files plus one line in CMakeLists.txt.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/integrator.h"
#include "integrators/params.h"

namespace pl {

struct IntegratorEntry {
  using Factory = std::function<std::unique_ptr<Integrator>(const ParamSet&, const RenderOptions&)>;
  using Resolve = std::function<std::string(const Scene&, int width, int height, ParamSet&)>;
  IntegratorEntry(std::string name, std::string summary, std::vector<ParamSpec> params, Factory make, Resolve resolve = {})
      : name(std::move(name)), summary(std::move(summary)), params(std::move(params)), make(std::move(make)),
        resolve(std::move(resolve)) {}

  std::string name;
  std::string summary;  // one line
  std::vector<ParamSpec> params;
  Factory make;
  // Optional: fills scene-dependent defaults into the parameters before rendering (so that the
  // metadata and the resolved config say what was used) and says what it chose, in words, for
  // the summary line ("" when there is nothing to say).
  Resolve resolve;

  // The parameter that is the render's budget unit ("spp" or "passes"), or nullptr.
  const ParamSpec* budgetParam() const;
  // A parameter set holding every default.
  ParamSet defaults() const { return ParamSet(&params); }
};

class IntegratorRegistration {
 public:
  explicit IntegratorRegistration(IntegratorEntry entry);
};

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

}  // namespace pl
