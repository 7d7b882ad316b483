// libFuzzer target: the glTF loader on arbitrary bytes (JSON with data-URI buffers, or GLB with
// its BIN chunk), then a tiny render of whatever loads. Bad input must end as pl::Error; any other
// exception, a crash, a sanitizer report, a NaN on the film or a hang is a finding.
// Build and run: scripts/fuzz.sh gltf SECONDS.
#include <cstdint>
#include <cstdlib>

#include "integrators/registry.h"
#include "photon/photon_tracer.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::unique_ptr<pl::Scene> scene;
  try {
    scene = pl::loadGltfFromMemory("fuzz.gltf", data, size);
  } catch (const pl::Error&) {
    return 0;
  }
  pl::RenderOptions o;
  o.width = 4;
  o.height = 4;
  o.spp = 1;
  o.threads = 1;
  for (const char* name : {"path", "photon"}) {
    pl::ParamSet params = pl::integratorEntry(name).defaults();
    if (params.has("photons")) {
      params.setNumber("photons", 64);
      params.setNumber("caustic_photons", 64);
      params.setNumber("final_gather", 2);
    }
    auto integrator = pl::makeIntegrator(name, params, o);
    pl::RenderInfo stats;
    pl::ImageRGB image = pl::render(*scene, *integrator, o, &stats);
    for (float v : image.data)
      if (!std::isfinite(v)) std::abort();  // non-finite samples must be discarded, never reach the film
  }
  return 0;
}
