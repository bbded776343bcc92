// libFuzzer target: the `evio` command line. The input is split at NUL bytes
// into arguments after "evio"; every command of the real executable is
// registered (experiments/apps/all_commands.cpp) with its work replaced by
// nothing, so what is fuzzed is the parser: CLI11 with every option, flag,
// validator and subcommand evio declares. Any argument list must parse or
// end in CLI::ParseError (exit 100-199) or evio::Error; nothing else.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"  // experiments/apps (evio_cli)
#include "evio/core/error.h"

namespace {
/// Takes a subcommand's callback out of it. Each command's callback owns the
/// variables its options write into (a shared_ptr it captures), so it must
/// outlive the parse: replacing it would free them under the parser (the
/// heap-use-after-free this harness first reported).
struct CallbackAccess : CLI::App {
  static std::function<void()> take(CLI::App& app) {
    constexpr auto member = &CallbackAccess::final_callback_;  // protected, reached through the derived class
    return std::exchange(app.*member, {});
  }
};

/// Replaces the work of `app` and of every subcommand below it by nothing,
/// keeping the original callbacks (and what they own) in `keep`.
void disarm(CLI::App& app, std::vector<std::function<void()>>& keep) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    keep.push_back(CallbackAccess::take(*sub));
    sub->callback([] {});
    disarm(*sub, keep);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args;
  std::string arg;
  for (std::size_t i = 0; i < size && args.size() < 64; ++i) {
    if (data[i] == 0) {
      args.push_back(arg);
      arg.clear();
    } else {
      arg.push_back(static_cast<char>(data[i]));
    }
  }
  if (args.size() < 64) args.push_back(arg);
  std::vector<const char*> argv{"evio"};
  for (const auto& a : args) argv.push_back(a.c_str());
  std::vector<std::function<void()>> keep;  // outlives app: the options' variables
  CLI::App app{"evio"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "fuzz");
  evio::apps::addAllCommands(app);
  disarm(app, keep);
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
  } catch (const evio::Error&) {
  }
  return 0;
}
