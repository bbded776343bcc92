#include "evio/core/io/config.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

#include "evio/core/eigen_types.h"
#include "evio/core/io/atomic_file.h"
#include "temp_dir.h"

namespace evio {
namespace {

struct InnerOptions {
  double threshold_pos = 0.2;  ///< positive contrast threshold
  int count = 3;               ///< a count
  template <class V>
  void fields(V& v) {
    v("threshold_pos", threshold_pos, "positive contrast threshold");
    v("count", count, "a count");
  }
  void validate() const { requirePositive("threshold_pos", threshold_pos); }
};

struct OuterOptions {
  double exposure_s = 0.01;
  bool enabled = true;
  std::string name = "default";
  std::vector<double> weights = {1.0, 2.0};
  Vec3 offset_m = Vec3(0.1, 0.2, 0.3);
  std::uint64_t seed = 7;
  InnerOptions inner;
  template <class V>
  void fields(V& v) {
    v("exposure_s", exposure_s, "exposure in seconds");
    v("enabled", enabled, "switch");
    v("name", name, "a name");
    v("weights", weights, "weights");
    v("offset_m", offset_m, "offset in metres");
    v("seed", seed, "seed");
    v("inner", inner, "nested options");
  }
  void validate() const {
    requirePositive("exposure_s", exposure_s);
    inner.validate();
  }
};

config::Document doc(const std::string& text) { return config::loadString(text, "test.yaml"); }

TEST(Config, FillsFieldsAndKeepsDefaults) {
  OuterOptions o;
  config::fill(doc("exposure_s: 0.02\ninner:\n  count: 5\noffset_m: [1, 2, 3]\n"), "", o);
  EXPECT_DOUBLE_EQ(o.exposure_s, 0.02);
  EXPECT_EQ(o.inner.count, 5);
  EXPECT_DOUBLE_EQ(o.inner.threshold_pos, 0.2);
  EXPECT_EQ(o.offset_m, Vec3(1, 2, 3));
  EXPECT_EQ(o.name, "default");
}

TEST(Config, UnknownKeyNamesFileAndLine) {
  OuterOptions o;
  try {
    config::fill(doc("exposure_s: 0.02\ninner:\n  count: 5\n  treshold_pos: 0.3\n"), "", o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("test.yaml:4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("inner.treshold_pos"), std::string::npos) << msg;
    EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
  }
}

TEST(Config, WrongTypeNamesFieldAndLine) {
  OuterOptions o;
  try {
    config::fill(doc("name: x\nexposure_s: fast\n"), "", o);
    FAIL();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("test.yaml:2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("exposure_s"), std::string::npos) << msg;
  }
  EXPECT_THROW(config::fill(doc("offset_m: [1, 2]\n"), "", o), Error);
  EXPECT_THROW(config::fill(doc("seed: -3\n"), "", o), Error);
  EXPECT_THROW(config::fill(doc("enabled: maybe\n"), "", o), Error);
  EXPECT_THROW(config::fill(doc("inner: 3\n"), "", o), Error);
  EXPECT_THROW(config::fill(doc("exposure_s: .nan\n"), "", o), Error);
}

// Found by fuzz_config_yaml: a tagged or complex key made yaml-cpp throw its
// own exception type instead of evio::Error.
TEST(Config, NonScalarKeysAreAnError) {
  OuterOptions o;
  EXPECT_THROW(config::fill(doc("exposure_s: 0.02\n? [a, b]\n: 3\n"), "", o), Error);
  EXPECT_THROW(config::fill(doc("exposure_s: 0.02\n!weights: [1, 2]\n"), "", o), Error);
}

TEST(Config, ValidateErrorNamesField) {
  OuterOptions o;
  try {
    config::fill(doc("inner:\n  threshold_pos: -1\n"), "", o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("threshold_pos"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos) << e.what();
  }
}

TEST(Config, OverridesApplyAndAreNamedInErrors) {
  auto d = doc("inner:\n  count: 5\n");
  config::applyOverride(d, "inner.threshold_pos=0.5");
  config::applyOverride(d, "exposure_s=0.03");
  config::applyOverride(d, "weights=[3, 4, 5]");
  OuterOptions o;
  config::fill(d, "", o);
  EXPECT_DOUBLE_EQ(o.inner.threshold_pos, 0.5);
  EXPECT_EQ(o.inner.count, 5);
  EXPECT_DOUBLE_EQ(o.exposure_s, 0.03);
  EXPECT_EQ(o.weights, (std::vector<double>{3, 4, 5}));

  auto bad = doc("");
  config::applyOverride(bad, "inner.cout=4");
  try {
    config::fill(bad, "", o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--set inner.cout"), std::string::npos) << e.what();
  }
  EXPECT_THROW(config::applyOverride(bad, "novalue"), Error);
  EXPECT_THROW(config::applyOverride(bad, "a..b=1"), Error);
}

TEST(Config, DefaultsRoundTripThroughYaml) {
  OuterOptions a;
  a.exposure_s = 0.1 + 0.2;  // not exactly representable in short decimal
  a.weights = {1e-300, -3.5};
  const std::string text = config::toYaml(a);
  OuterOptions b;
  b.exposure_s = 1.0;
  config::fill(doc(text), "", b);
  EXPECT_TRUE(config::equal(a, b)) << text;
  EXPECT_EQ(a.exposure_s, b.exposure_s);
  b.inner.count = 99;
  EXPECT_FALSE(config::equal(a, b));
}

TEST(Config, NumbersAreWrittenSoEveryYamlReaderTakesThemForNumbers) {
  EXPECT_EQ(config::yamlNumber(10.0), "10");
  EXPECT_EQ(config::yamlNumber(90.0), "90");
  EXPECT_EQ(config::yamlNumber(2e4), "20000");
  EXPECT_EQ(config::yamlNumber(-0.0), "0");
  EXPECT_EQ(config::yamlNumber(0.25), "0.25");
  EXPECT_EQ(config::yamlNumber(1e-5), "1.0e-05");
  EXPECT_EQ(config::yamlNumber(2.5e-7), "2.5e-07");
  EXPECT_EQ(config::yamlNumber(1e20), "1.0e+20");
  EXPECT_EQ(config::yamlNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(config::yamlNumber(-std::numeric_limits<double>::infinity()), "-.inf");
  EXPECT_EQ(config::yamlNumber(std::numeric_limits<double>::quiet_NaN()), ".nan");
  // Each reads back exactly (yaml-cpp), and PyYAML (YAML 1.1, Debian's
  // python3-yaml) parses every written number as an int or a float.
  OuterOptions a;
  a.exposure_s = 10.0;
  a.weights = {1e-5, 90.0, 2e4, 1e20, 0.1 + 0.2, 2.5e-7};
  a.offset_m = Vec3(1e-12, -3.0, 1e16);
  const std::string text = config::toYaml(a);
  OuterOptions b;
  config::fill(doc(text), "", b);
  EXPECT_TRUE(config::equal(a, b)) << text;
  test::TempDir dir;
  io::writeFileAtomic(dir.file("numbers.yaml"), text);
  const std::string check =
      "/usr/bin/python3 -c \"import sys, yaml\n"
      "d = yaml.safe_load(open(sys.argv[1]))\n"
      "nums = [d['exposure_s'], d['inner']['threshold_pos']] + d['weights'] + d['offset_m']\n"
      "bad = [x for x in nums if not isinstance(x, (int, float))]\n"
      "sys.exit(1 if bad else 0)\" " +
      dir.file("numbers.yaml");
  EXPECT_EQ(std::system(check.c_str()), 0) << text;
}

TEST(Config, SyntaxErrorAndMissingFile) {
  EXPECT_THROW(config::loadString("a: [1, 2\n", "x.yaml"), Error);
  try {
    config::loadFile("/nonexistent/evio.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/evio.yaml"), std::string::npos);
  }
}

TEST(AtomicFile, UncommittedLeavesNothing) {
  test::TempDir dir;
  const std::string path = dir.file("out.txt");
  {
    io::AtomicFile f(path);
    f.write("partial");
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  io::writeFileAtomic(path, "done");
  EXPECT_EQ(io::readFile(path), "done");
}

}  // namespace
}  // namespace evio
