// `evio report <results> [-o <folder>]`: Markdown and CSV tables of a
// campaign's results (summary.csv, written by `evio campaign` and `evio
// campaign collect`) and PNG plots by experiments/plots/campaign_report.py:
// Monte Carlo box plots, success rates, error against distance and time,
// trajectories in top view, NEES over time with its bounds, real-time factor
// against event rate. Plots whose inputs are absent are skipped, with a note.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/experiments/campaign_report.h"
#include "evio/experiments/campaign_results.h"
#include "plot_runner.h"

namespace evio::apps {

void addReportCommand(CLI::App& app) {
  struct Args {
    std::string results;
    std::string output;
    std::string title;
    bool no_plots = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("report", "Tables (Markdown, CSV) and plots of a campaign's results");
  cmd->add_option("results", args->results, "campaign results folder (with summary.csv)")->required();
  cmd->add_option("-o,--output", args->output, "report folder (default <results>/report)");
  cmd->add_option("--title", args->title, "report title (default: the results folder's name)");
  cmd->add_flag("--no-plots", args->no_plots, "tables only");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    const fs::path results(args->results);
    const fs::path out = args->output.empty() ? results / "report" : fs::path(args->output);
    const std::string summary = (results / "summary.csv").string();
    if (!fs::is_regular_file(summary))
      throw Error(summary + ": not found (run `evio campaign` or `evio campaign collect` first)");
    const auto report = experiments::aggregateSummary(experiments::parseCsv(io::readFile(summary)));
    fs::create_directories(out);
    io::writeFileAtomic((out / "groups.csv").string(), experiments::reportCsv(report));

    std::vector<std::string> notes;
    if (args->no_plots) {
      notes.emplace_back("plots not drawn (--no-plots)");
    } else {
      fs::remove(out / "plots.txt");
      const std::string problem =
          runPlotScript("campaign_report.py", {results.string(), out.string(), (out / "groups.csv").string()});
      if (!problem.empty()) {
        std::fprintf(stderr, "evio: warning: %s\n", problem.c_str());
        notes.push_back(problem);
      }
      // The script lists what it drew and what it skipped (and why).
      if (fs::is_regular_file(out / "plots.txt")) {
        const std::string text = io::readFile((out / "plots.txt").string());
        std::size_t begin = 0;
        while (begin < text.size()) {
          const std::size_t end = text.find('\n', begin);
          const std::string line = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
          if (line.rfind("skipped ", 0) == 0) notes.push_back(line);
          if (end == std::string::npos) break;
          begin = end + 1;
        }
      }
    }
    std::vector<std::string> figures;
    if (fs::is_directory(out))
      for (const auto& e : fs::directory_iterator(out))
        if (e.path().extension() == ".png") figures.push_back(e.path().filename().string());
    std::sort(figures.begin(), figures.end());
    const std::string title =
        args->title.empty() ? "Campaign report: " + fs::absolute(results).lexically_normal().filename().string()
                            : args->title;
    io::writeFileAtomic((out / "report.md").string(), experiments::reportMarkdown(report, title, figures, notes));
    if (!args->quiet)
      std::printf("report: %s (%zu groups, %zu of %zu jobs finished, %zu figures, %zu notes)\n",
                  (out / "report.md").string().c_str(), report.groups.size(), report.finished, report.jobs,
                  figures.size(), notes.size());
  });
}

}  // namespace evio::apps
