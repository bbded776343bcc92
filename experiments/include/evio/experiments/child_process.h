#pragma once
/// @file child_process.h
/// Runs an external command as a child process (fork + exec, no shell), so
/// that a crashing or hanging step cannot take the caller down. The child
/// runs in its own process group in `cwd` with stdout and stderr appended to
/// a log file; it is killed (SIGKILL) when the caller dies
/// (PR_SET_PDEATHSIG) or when it exceeds its time limit (the whole group).
/// Safe to call from several threads at once.

#include <string>
#include <vector>

namespace evio::experiments {

struct ChildResult {
  bool started = false;    ///< false: the command could not be executed (see error)
  int exit_code = -1;      ///< when it exited normally
  int signal = 0;          ///< when killed by a signal
  bool timed_out = false;
  double wall_s = 0.0;
  std::string error;       ///< why it did not start

  bool ok() const { return started && !timed_out && signal == 0 && exit_code == 0; }
  /// "exit code 3", "killed by signal 11 (Segmentation fault)", "timed out after 60 s", "cannot execute …".
  std::string describe() const;
};

/// Runs argv[0] (a path, or a name looked up on PATH) with `argv`.
/// `timeout_s` <= 0: no limit. Throws evio::Error only for an empty argv or
/// a log file that cannot be opened.
ChildResult runChild(const std::vector<std::string>& argv, const std::string& cwd, const std::string& log_path,
                     double timeout_s);

/// The last non-empty line of a (small or large) text file, for error causes; "" if none.
std::string lastLineOf(const std::string& path);

}  // namespace evio::experiments
