#include "integrators/builtins.h"

namespace pl {

std::vector<IntegratorEntry> builtinIntegrators() {
  std::vector<IntegratorEntry> all;
  for (IntegratorEntry (*entry)() : {bdptEntry, bpmEntry, directEntry, guidedEntry, lightEntry, pathEntry, photonEntry, ppmEntry,
                                     pppmEntry, radiosityEntry, sppmEntry, vcmEntry, whittedEntry})
    all.push_back(entry());
  return all;
}

}  // namespace pl
