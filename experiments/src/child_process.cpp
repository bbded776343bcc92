#include "evio/experiments/child_process.h"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <thread>

#include "evio/core/error.h"
#include "evio/core/stopwatch.h"

namespace evio::experiments {

std::string ChildResult::describe() const {
  char buf[160];
  if (!started) return "cannot execute: " + error;
  if (timed_out) {
    std::snprintf(buf, sizeof(buf), "timed out after %.0f s", wall_s);
    return buf;
  }
  if (signal != 0) {
    std::snprintf(buf, sizeof(buf), "killed by signal %d (%s)", signal, strsignal(signal));
    return buf;
  }
  return "exit code " + std::to_string(exit_code);
}

ChildResult runChild(const std::vector<std::string>& argv, const std::string& cwd, const std::string& log_path,
                     double timeout_s) {
  require(!argv.empty(), "runChild: empty command");
  ChildResult r;
  // Everything the child needs is prepared before fork: between fork and
  // exec only async-signal-safe calls are made.
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int log_fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) throw Error(log_path + ": cannot open log file: " + std::strerror(errno));
  int status_pipe[2];  // reports an exec failure (errno) to the parent; closed on exec
  if (::pipe2(status_pipe, O_CLOEXEC) != 0) {
    ::close(log_fd);
    throw Error("runChild: pipe failed");
  }
  const pid_t parent = ::getpid();
  const Stopwatch watch;
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log_fd);
    ::close(status_pipe[0]);
    ::close(status_pipe[1]);
    r.error = std::string("fork failed: ") + std::strerror(errno);
    return r;
  }
  if (pid == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);  // the parent died before prctl
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    ::dup2(log_fd, STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    int err = 0;
    if (!cwd.empty() && ::chdir(cwd.c_str()) != 0) {
      err = errno;
    } else {
      ::execvp(args[0], args.data());
      err = errno;
    }
    [[maybe_unused]] const ssize_t n = ::write(status_pipe[1], &err, sizeof(err));
    ::_exit(127);
  }
  ::close(log_fd);
  ::close(status_pipe[1]);
  int exec_errno = 0;
  const ssize_t got = ::read(status_pipe[0], &exec_errno, sizeof(exec_errno));
  ::close(status_pipe[0]);
  int status = 0;
  auto sleep = std::chrono::milliseconds(2);
  for (;;) {
    const pid_t w = ::waitpid(pid, &status, timeout_s > 0.0 ? WNOHANG : 0);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) {
      r.error = std::string("waitpid failed: ") + std::strerror(errno);
      return r;
    }
    const double elapsed = watch.seconds();
    if (timeout_s > 0.0 && elapsed > timeout_s && !r.timed_out) {
      r.timed_out = true;
      ::kill(-pid, SIGKILL);
      ::kill(pid, SIGKILL);
    }
    if (w == 0) {
      std::this_thread::sleep_for(sleep);
      sleep = std::min(sleep * 2, std::chrono::milliseconds(50));
    }
  }
  r.wall_s = watch.seconds();
  if (got == static_cast<ssize_t>(sizeof(exec_errno))) {
    r.error = argv[0] + ": " + std::strerror(exec_errno);
    return r;
  }
  r.started = true;
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  if (r.timed_out) r.signal = 0;
  return r;
}

std::string lastLineOf(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return "";
  std::fseek(f, 0, SEEK_END);
  const long size = std::ftell(f);
  const long from = size > 4096 ? size - 4096 : 0;
  std::fseek(f, from, SEEK_SET);
  std::string tail(static_cast<std::size_t>(size - from), '\0');
  const std::size_t n = std::fread(tail.data(), 1, tail.size(), f);
  std::fclose(f);
  tail.resize(n);
  while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r' || tail.back() == ' ')) tail.pop_back();
  const std::size_t nl = tail.find_last_of("\n\r");
  std::string line = nl == std::string::npos ? tail : tail.substr(nl + 1);
  if (line.size() > 300) line = line.substr(0, 300) + "…";
  return line;
}

}  // namespace evio::experiments
