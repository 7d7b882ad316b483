// libFuzzer target: the experiment-config parser on arbitrary bytes. Bad input must end as
// pl::Error naming the file; anything else (another exception, a crash, a sanitizer report) is a
// finding. A config that parses must also survive writing its resolved form and parsing that.
// Build and run: scripts/fuzz.sh experiment SECONDS.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "experiment/config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  try {
    pl::ExperimentConfig c = pl::parseExperiment(text, "fuzz.toml");
    pl::ExperimentConfig again = pl::parseExperiment(pl::resolvedConfigToml(c, {}), "fuzz.toml");
    if (again.runs.size() != c.runs.size()) std::abort();
    for (size_t i = 0; i < c.runs.size(); ++i)
      if (pl::settingsFingerprint(again.runs[i].settings) != pl::settingsFingerprint(c.runs[i].settings)) std::abort();
  } catch (const pl::Error&) {
  }
  return 0;
}
