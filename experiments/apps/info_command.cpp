// `evio info <sequence-folder>`: what a sequence contains and what is missing.
#include <cstdio>
#include <string>

#include "commands.h"
#include "evio/core/io/staged_folder.h"
#include "evio/experiments/sequence_info.h"
#include "progress_line.h"

namespace evio::apps {

void addInfoCommand(CLI::App& app) {
  struct Args {
    std::string folder;
    bool json = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("info", "Summarise a sequence folder (Event-Camera Dataset layout)");
  cmd->add_option("folder", args->folder, "sequence folder")->required();
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress line");
  cmd->callback([args] {
    ProgressLine progress("reading events", "ev", args->quiet);
    io::requireNotStaging(args->folder);
    const auto info = experiments::inspectSequence(args->folder, [&](double fraction, std::uint64_t events) {
      progress.update(fraction, static_cast<double>(events));
    });
    progress.finish();
    const std::string text = args->json ? experiments::sequenceInfoJson(info) : experiments::formatSequenceInfo(info);
    std::fputs(text.c_str(), stdout);
  });
}

}  // namespace evio::apps
