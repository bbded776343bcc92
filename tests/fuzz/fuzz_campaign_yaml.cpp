// libFuzzer target: the campaign loader and its job matrix
// (experiments/campaign.h). The input is written as
// <tmp>/experiments/campaigns/fuzz.yaml beside links to the repository's
// trajectories/ and experiments/scenarios/, so the seeds'
// (experiments/campaigns/*.yaml) relative scenario paths resolve as in the
// repository. Any input must load and expand or throw evio::Error.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "evio/core/error.h"
#include "evio/experiments/campaign.h"

namespace {
/// A scratch tree <tmp>/experiments/campaigns with links to the repository.
std::string campaignFolder() {
  static const std::string folder = [] {
    char tmpl[] = "/tmp/evio_fuzz_XXXXXX";
    const char* d = ::mkdtemp(tmpl);
    if (!d) __builtin_trap();
    const std::string root = d;
    const std::string src = EVIO_SOURCE_DIR;
    ::mkdir((root + "/experiments").c_str(), 0700);
    ::mkdir((root + "/experiments/campaigns").c_str(), 0700);
    for (const char* link : {"trajectories", "scenes", "simulator", "estimator", "experiments/scenarios"})
      if (::symlink((src + "/" + link).c_str(), (root + "/" + link).c_str()) != 0) __builtin_trap();
    return root + "/experiments/campaigns";
  }();
  return folder;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = campaignFolder() + "/fuzz.yaml";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) __builtin_trap();
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const evio::experiments::Campaign c = evio::experiments::loadCampaign(path);
    (void)evio::experiments::expandJobs(c);
  } catch (const evio::Error&) {
  }
  return 0;
}
