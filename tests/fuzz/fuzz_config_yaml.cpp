// libFuzzer target: the YAML configuration loader filling a nested Options
// struct (unknown keys, wrong types, syntax errors must all be evio::Error).
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/io/config.h"

namespace {
struct Inner {
  double threshold_pos = 0.2;
  int count = 3;
  template <class V>
  void fields(V& v) {
    v("threshold_pos", threshold_pos);
    v("count", count);
  }
  void validate() const { evio::requirePositive("threshold_pos", threshold_pos); }
};
struct Outer {
  double exposure_s = 0.01;
  bool enabled = true;
  std::string name;
  std::vector<double> weights;
  evio::Vec3 offset_m = evio::Vec3::Zero();
  std::uint64_t seed = 0;
  Inner inner;
  template <class V>
  void fields(V& v) {
    v("exposure_s", exposure_s);
    v("enabled", enabled);
    v("name", name);
    v("weights", weights);
    v("offset_m", offset_m);
    v("seed", seed);
    v("inner", inner);
  }
  void validate() const { inner.validate(); }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    auto doc = evio::config::loadString(text, "fuzz.yaml");
    Outer o;
    evio::config::fill(doc, "", o);
    (void)evio::config::toYaml(o);
  } catch (const evio::Error&) {
  }
  return 0;
}
