// The built-in integrators, each declared in its own file and registered here by name: a new
// one is its file plus one line in builtins.cpp (and CMakeLists.txt's source list). Explicit
// calls, not static self-registration, so that a normal static link keeps every integrator.
#pragma once
#include "integrators/registry.h"

namespace pl {

IntegratorEntry bdptEntry();       // bidirectional.cpp
IntegratorEntry bpmEntry();        // bidirectional.cpp
IntegratorEntry directEntry();     // direct.cpp
IntegratorEntry guidedEntry();     // guided.cpp
IntegratorEntry lightEntry();      // light.cpp
IntegratorEntry pathEntry();       // path.cpp
IntegratorEntry photonEntry();     // photon.cpp
IntegratorEntry ppmEntry();        // ppm.cpp
IntegratorEntry pppmEntry();       // pppm.cpp
IntegratorEntry radiosityEntry();  // radiosity.cpp
IntegratorEntry sppmEntry();       // sppm.cpp
IntegratorEntry vcmEntry();        // bidirectional.cpp
IntegratorEntry whittedEntry();    // whitted.cpp

// Every built-in entry, in the order above.
std::vector<IntegratorEntry> builtinIntegrators();

}  // namespace pl
