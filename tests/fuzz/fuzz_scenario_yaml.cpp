// libFuzzer target: the scenario loader (simulator/scenario.h) on YAML text,
// with scene and trajectory presets resolved against the repository as
// `evio simulate` does. Any input must load (and print its resolved YAML) or
// throw evio::Error; nothing else is acceptable. Seeds:
// experiments/scenarios/*.yaml.
#include "evio/core/error.h"
#include "evio/simulator/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string root = EVIO_SOURCE_DIR;
  try {
    const evio::simulator::Scenario s =
        evio::simulator::loadScenarioString(text, "fuzz.yaml", root + "/experiments/scenarios", {}, root);
    (void)s.sensorRig();
    (void)s.resolvedYaml();
  } catch (const evio::Error&) {
  }
  return 0;
}
