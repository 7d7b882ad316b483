// Integrators by name, through the registry, as `photonlab render` and experiments make them.
#pragma once
#include <map>
#include <string>

#include "integrators/registry.h"
#include "render/renderer.h"

namespace pl::test {

// `values` sets declared parameters by name (numbers; `choices` for text ones). A name the
// integrator does not declare is skipped, so that one list serves a loop over several
// integrators (as `photons` for path and photon).
inline std::unique_ptr<Integrator> makeWith(const std::string& name, const std::map<std::string, double>& values,
                                            const RenderOptions& image = {},
                                            const std::map<std::string, std::string>& choices = {}) {
  ParamSet p = integratorEntry(name).defaults();
  for (auto& [k, v] : values)
    if (p.has(k)) p.setNumber(k, v);
  for (auto& [k, v] : choices)
    if (p.has(k)) p.setChoice(k, v);
  return makeIntegrator(name, p, image);
}

}  // namespace pl::test
