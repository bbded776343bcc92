#include "plot_runner.h"

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include "data_root.h"

namespace evio::apps {

std::string runPlotScript(const std::string& script, const std::vector<std::string>& args) {
  const char* env_dir = std::getenv("EVIO_PLOTS_DIR");
  std::filesystem::path dir;
  try {
    dir = env_dir ? std::filesystem::path(env_dir) : dataRoot() / "experiments" / "plots";
  } catch (const std::exception& e) {
    return std::string("plot skipped: ") + e.what();
  }
  const std::string path = (dir / script).string();
  const char* python = "/usr/bin/python3";
  if (!std::filesystem::exists(path)) return "plot script not found: " + path;
  if (::access(python, X_OK) != 0) return "plot skipped: /usr/bin/python3 is missing (scripts/install_deps.sh installs it)";
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(python));
  argv.push_back(const_cast<char*>(path.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) return "plot failed: cannot fork";
  if (pid == 0) {
    // The plot dies with evio (SIGINT/SIGTERM end evio at once): no orphan
    // keeps writing after an interrupted command.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::execv(python, argv.data());
    ::_exit(127);
  }
  int status = 0;
  if (::waitpid(pid, &status, 0) < 0) return "plot failed: waitpid";
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return "plot failed: " + path + " exited with status " + std::to_string(WEXITSTATUS(status));
  return {};
}

}  // namespace evio::apps
