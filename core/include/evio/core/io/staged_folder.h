#pragma once
/// @file staged_folder.h
/// Outputs as transactions. A command writes its output folder under a
/// staging name beside the target ("<target>.staging.<pid>") and publishes it
/// with one rename, replacing an existing target whole: a reader sees the
/// previous complete output, the new complete output, or nothing, never a mix.
///
/// Interruption: paths registered with `InterruptCleanup` (staging folders,
/// temporary files) are removed by the SIGINT/SIGTERM handlers that
/// `installInterruptHandlers()` installs; the handler uses only
/// async-signal-safe system calls and ends the process with 128 + signal.
/// What a SIGKILL leaves behind is removed by the next run into the same
/// target (`removeStaleStaging`).
///
/// Fault injection (builds with EVIO_FAULT_INJECTION, i.e. test builds):
/// every write, commit and rename passes `faultPoint()`, which counts them
/// and, when the environment asks (EVIO_FAULT_AFTER=N, EVIO_FAULT=SIGINT |
/// SIGTERM | SIGKILL | EIO), raises that signal or fails that write at the
/// N-th point. Without the macro `faultPoint()` does nothing.

#include <cstddef>
#include <string>
#include <vector>

namespace evio::io {

/// Installs the SIGINT/SIGTERM handlers that remove every registered path
/// and exit with 128 + signal; ignores SIGXFSZ so that a file-size limit is
/// a write error, not a kill. Call once from main().
void installInterruptHandlers();

/// Registers `path` (a file or a folder) for removal on SIGINT/SIGTERM while
/// the object lives. At most 256 registrations at once; more are not tracked.
///
/// Threads: the handler may run on any thread while others register, create,
/// publish or release. Protocol: register, create the path, call
/// confirmCreated(); before renaming the path into place call beginPublish()
/// (the handler then leaves it alone), and release() after. A thread that
/// finds the handler running blocks until the process ends.
class InterruptCleanup {
 public:
  enum class Scope {
    kPath,              ///< the path only
    kWithChildStaging,  ///< also "<path>.staging.<pid>" that a child process writes (e.g. `evio simulate -o <path>`)
  };
  InterruptCleanup() = default;
  explicit InterruptCleanup(const std::string& path, Scope scope = Scope::kPath);
  ~InterruptCleanup();
  InterruptCleanup(const InterruptCleanup&) = delete;
  InterruptCleanup& operator=(const InterruptCleanup&) = delete;
  InterruptCleanup(InterruptCleanup&& other) noexcept;
  InterruptCleanup& operator=(InterruptCleanup&& other) noexcept;
  /// Call once the path exists: if the handler already ran on another
  /// thread, removes the path and blocks until the process ends.
  void confirmCreated() const;
  /// The path is about to be renamed into place: the handler must not empty
  /// it meanwhile. Blocks for good when the handler already claimed it.
  void beginPublish();
  /// The rename failed: the handler removes the path again on a signal.
  void cancelPublish();
  /// Stops tracking (the path was published or removed).
  void release();

 private:
  int slot_ = -1;
};

/// True for a name this module gives to unfinished or replaced output:
/// "<x>.staging.<pid>", "<x>.old.<pid>" or "<x>.tmp.<pid>.<n>".
bool isStagingName(const std::string& path);

/// Throws Error naming `path` when it is a staging name (an interrupted or
/// unpublished output): consumers never read one.
void requireNotStaging(const std::string& path);

/// Checks that `target` can be an output folder: no parent is a file, and the
/// target is absent or a folder. Throws Error naming the offending path.
void checkOutputFolder(const std::string& target);

/// Checks that `target` can be an output file: its folder exists (or can be
/// made) and is a folder, and the target is absent or a regular file.
void checkOutputFile(const std::string& target);

/// Removes staging and temporary leftovers of dead processes beside `target`
/// ("<target>.staging.<pid>", "<target>.tmp.<pid>.<n>"); a "<target>.old.<pid>"
/// of a dead process is moved back to `target` when `target` is missing (a
/// publication killed half-way), else removed. Returns how many were handled.
std::size_t removeStaleStaging(const std::string& target);

/// Publishes the folder `staging` as `target` by one rename; an existing
/// target is replaced whole (exchanged atomically where the file system
/// supports it, else renamed aside first and removed after). Throws Error
/// naming the paths on failure, leaving the previous target in place.
void publishFolder(const std::string& staging, const std::string& target);

/// An output folder being written: `path()` is the staging folder, created
/// empty on construction (after removing stale leftovers and checking the
/// target's kind); `publish()` makes it the target. Destruction without
/// publish removes the staging folder.
class StagedFolder {
 public:
  explicit StagedFolder(std::string target);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  const std::string& path() const { return staging_; }
  const std::string& target() const { return target_; }
  void publish();

 private:
  std::string target_;
  std::string staging_;
  InterruptCleanup cleanup_;
  bool published_ = false;
};

/// Output files that belong together (a main file and sidecars beside it,
/// e.g. metrics.json with metrics_poses.csv): each is written under
/// `path(final)` in a staging folder beside the main file; `publish()`
/// removes the previous main file, moves the sidecars in and the main file
/// last, so a main file is always accompanied by its own sidecars.
class StagedFiles {
 public:
  explicit StagedFiles(std::string main_file);
  ~StagedFiles();
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;

  /// Where to write `final_path` (the main file or a sidecar in its folder).
  std::string path(const std::string& final_path);
  /// A sidecar this run does not write: an old one is removed on publish.
  void drop(const std::string& final_path);
  void publish();

 private:
  std::string main_;
  std::string staging_;
  std::vector<std::string> finals_;
  std::vector<std::string> dropped_;
  InterruptCleanup cleanup_;
  bool published_ = false;
};

/// A point where a fault may be injected (see the file comment). `path` names
/// the file in the error of an injected write failure.
void faultPoint(const std::string& path);

/// Number of fault points passed so far by this process.
std::size_t faultPointsPassed();

/// When EVIO_FAULT_COUNT_FILE is set (fault-injection builds), writes the
/// number of fault points passed to that file. Called at the end of main().
void writeFaultCount();

}  // namespace evio::io
