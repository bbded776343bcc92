// Staged outputs (staged_folder.h): names of unfinished output, checks,
// publication by one rename, leftovers of dead processes, fault injection.
// The interrupt clean-up they register with is in interrupt_cleanup.cpp.
#include "evio/core/io/staged_folder.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "evio/core/error.h"

namespace evio::io {

namespace fs = std::filesystem;

namespace {

bool allDigits(const std::string& s) {
  if (s.empty()) return false;
  for (const char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

/// The largest PID of this system (/proc/sys/kernel/pid_max; 4194304 when unreadable).
long maxPid() {
  static const long max = [] {
    long v = 4194304;
    if (std::FILE* f = std::fopen("/proc/sys/kernel/pid_max", "r")) {
      if (std::fscanf(f, "%ld", &v) != 1) v = 4194304;
      std::fclose(f);
    }
    return v;
  }();
  return max;
}

bool processAlive(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

std::string errnoText(int e) { return std::error_code(e, std::generic_category()).message(); }

#ifdef EVIO_FAULT_INJECTION
struct FaultPlan {
  std::size_t after = 0;  // 0: never
  int action = 0;         // a signal number, or -1 for a failed write
};
const FaultPlan& faultPlan() {
  static const FaultPlan plan = [] {
    FaultPlan p;
    const char* after = std::getenv("EVIO_FAULT_AFTER");
    const char* what = std::getenv("EVIO_FAULT");
    if (!after || !what) return p;
    p.after = static_cast<std::size_t>(std::strtoull(after, nullptr, 10));
    const std::string w = what;
    p.action = w == "SIGINT" ? SIGINT : w == "SIGTERM" ? SIGTERM : w == "SIGKILL" ? SIGKILL : w == "EIO" ? -1 : 0;
    if (p.action == 0) p.after = 0;
    return p;
  }();
  return plan;
}
#endif
std::atomic<std::size_t> g_fault_points{0};

}  // namespace

// ---- names and kinds ----------------------------------------------------------

bool isStagingName(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  if (name.empty()) name = fs::path(path).parent_path().filename().string();  // "a/b/"
  const auto tail = [&](const std::string& marker) {
    const std::size_t at = name.rfind(marker);
    return at != std::string::npos && at > 0 ? name.substr(at + marker.size()) : std::string("x");
  };
  if (allDigits(tail(".staging.")) || allDigits(tail(".old."))) return true;
  // "<x>.tmp.<pid>.<n>" (AtomicFile) and "<x>.tmp.<host>.<pid>.<n>" (campaign sequences)
  const std::size_t tmp = name.rfind(".tmp.");
  if (tmp == std::string::npos || tmp == 0) return false;
  const std::string rest = name.substr(tmp + 5);
  const std::size_t last = rest.rfind('.');
  if (last == std::string::npos || last == 0 || !allDigits(rest.substr(last + 1))) return false;
  const std::size_t before = rest.rfind('.', last - 1);
  const std::size_t from = before == std::string::npos ? 0 : before + 1;
  return allDigits(rest.substr(from, last - from));
}

void requireNotStaging(const std::string& path) {
  if (isStagingName(path))
    throw Error(path + ": an unfinished or interrupted output (staging or temporary name); not read");
}

namespace {
/// Checks every existing parent of `target` is a folder.
void checkParents(const std::string& target) {
  fs::path p = fs::path(target).parent_path();
  while (!p.empty()) {
    std::error_code ec;
    const fs::file_status st = fs::status(p, ec);
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
      throw Error(p.string() + ": " + ec.message() + " (output " + target + ")");
    if (fs::exists(st)) {
      if (!fs::is_directory(st))
        throw Error(p.string() + ": not a folder (the output " + target + " would be under a file)");
      return;
    }
    if (p == p.parent_path()) return;
    p = p.parent_path();
  }
}
}  // namespace

void checkOutputFolder(const std::string& target) {
  if (target.empty()) throw Error("output folder: empty path");
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(target, ec);
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
    throw Error(target + ": " + ec.message());
  // Publication replaces the folder itself (an atomic exchange), never through a link.
  if (fs::is_symlink(st))
    throw Error(target + ": is a symbolic link; give the output folder's own path (output folder)");
  if (fs::exists(st) && !fs::is_directory(st)) throw Error(target + ": exists and is not a folder (output folder)");
  checkParents(target);
}

void checkOutputFile(const std::string& target) {
  if (target.empty()) throw Error("output file: empty path");
  std::error_code ec;
  const fs::file_status st = fs::status(target, ec);
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
    throw Error(target + ": " + ec.message());
  if (fs::exists(st) && !fs::is_regular_file(st)) throw Error(target + ": exists and is not a file (output file)");
  checkParents(target);
}

// ---- stale leftovers, publication -----------------------------------------------

std::size_t removeStaleStaging(const std::string& target) {
  const fs::path t(target);
  fs::path dir = t.parent_path();
  const std::string base = t.filename().string();
  if (base.empty()) return 0;
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  std::size_t handled = 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= base.size() + 1 || name.compare(0, base.size() + 1, base + ".") != 0) continue;
    const std::string rest = name.substr(base.size() + 1);  // "staging.<pid>", "old.<pid>", "tmp.<pid>.<n>"
    std::string pid_text;
    bool old = false;
    if (rest.rfind("staging.", 0) == 0) pid_text = rest.substr(8);
    else if (rest.rfind("old.", 0) == 0) pid_text = rest.substr(4), old = true;
    else if (rest.rfind("tmp.", 0) == 0) {  // AtomicFile's "tmp.<pid>.<n>" exactly
      const std::size_t dot = rest.find('.', 4);
      if (dot != std::string::npos && allDigits(rest.substr(dot + 1))) pid_text = rest.substr(4, dot - 4);
    }
    if (!allDigits(pid_text) || pid_text.size() > 12) continue;
    const long pid = std::strtol(pid_text.c_str(), nullptr, 10);
    // Not a PID of this system (e.g. a user's "out.old.20240101"): not ours.
    if (pid > maxPid() || processAlive(pid)) continue;
    std::error_code rec;
    if (old && !fs::exists(t, rec)) {
      fs::rename(e.path(), t, rec);  // a publication killed half-way: the previous output returns
      if (!rec) {
        ++handled;
        continue;
      }
    }
    fs::remove_all(e.path(), rec);
    ++handled;
  }
  return handled;
}

void publishFolder(const std::string& staging, const std::string& target) {
  faultPoint(target);
  struct stat st {};
  if (::lstat(target.c_str(), &st) != 0) {
    if (errno != ENOENT) throw Error(target + ": cannot publish the output: " + errnoText(errno));
    if (std::rename(staging.c_str(), target.c_str()) != 0)
      throw Error(target + ": cannot publish the output (rename from " + staging + "): " + errnoText(errno));
    return;
  }
  if (!S_ISDIR(st.st_mode)) throw Error(target + ": exists and is not a folder (output folder)");
  // Swap the two folders in one step; `staging` then holds the previous output.
  if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    return;
  }
  if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
    throw Error(target + ": cannot publish the output (exchange with " + staging + "): " + errnoText(errno));
  // No exchange on this file system: the previous output aside, the new one in.
  const std::string old = target + ".old." + std::to_string(::getpid());
  if (std::rename(target.c_str(), old.c_str()) != 0)
    throw Error(target + ": cannot move the previous output aside: " + errnoText(errno));
  faultPoint(target);
  if (std::rename(staging.c_str(), target.c_str()) != 0) {
    const int e = errno;
    if (std::rename(old.c_str(), target.c_str()) != 0)
      throw Error(target + ": cannot publish the output (rename from " + staging + "): " + errnoText(e) +
                  "; the previous output is in " + old);
    throw Error(target + ": cannot publish the output (rename from " + staging + "): " + errnoText(e));
  }
  std::error_code ec;
  fs::remove_all(old, ec);
}

StagedFolder::StagedFolder(std::string target) : target_(std::move(target)) {
  while (target_.size() > 1 && target_.back() == '/') target_.pop_back();
  checkOutputFolder(target_);
  removeStaleStaging(target_);
  staging_ = target_ + ".staging." + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(staging_, ec);
  const fs::path parent = fs::path(target_).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec) throw Error(parent.string() + ": cannot create the folder: " + ec.message());
  cleanup_ = InterruptCleanup(staging_);
  if (::mkdir(staging_.c_str(), 0777) != 0)
    throw Error(staging_ + ": cannot create the staging folder: " + errnoText(errno));
  cleanup_.confirmCreated();
}

StagedFolder::~StagedFolder() {
  if (published_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void StagedFolder::publish() {
  if (published_) throw Error(target_ + ": published twice");
  cleanup_.beginPublish();
  try {
    publishFolder(staging_, target_);
  } catch (...) {
    cleanup_.cancelPublish();
    throw;
  }
  published_ = true;
  cleanup_.release();
}

StagedFiles::StagedFiles(std::string main_file) : main_(std::move(main_file)) {
  checkOutputFile(main_);
  removeStaleStaging(main_);
  staging_ = main_ + ".staging." + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(staging_, ec);
  const fs::path parent = fs::path(main_).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec) throw Error(parent.string() + ": cannot create the folder: " + ec.message());
  cleanup_ = InterruptCleanup(staging_);
  if (::mkdir(staging_.c_str(), 0777) != 0)
    throw Error(staging_ + ": cannot create the staging folder: " + errnoText(errno));
  cleanup_.confirmCreated();
}

StagedFiles::~StagedFiles() {
  if (published_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

std::string StagedFiles::path(const std::string& final_path) {
  if (fs::path(final_path).parent_path() != fs::path(main_).parent_path())
    throw Error(final_path + ": an output beside " + main_ + " must be in its folder");
  if (final_path != main_) checkOutputFile(final_path);
  finals_.push_back(final_path);
  return (fs::path(staging_) / fs::path(final_path).filename()).string();
}

void StagedFiles::drop(const std::string& final_path) { dropped_.push_back(final_path); }

void StagedFiles::publish() {
  if (published_) throw Error(main_ + ": published twice");
  cleanup_.beginPublish();
  struct Cancel {  // a failed publication leaves the staging folder to the handler again
    InterruptCleanup& c;
    bool armed = true;
    ~Cancel() {
      if (armed) c.cancelPublish();
    }
  } cancel{cleanup_};
  faultPoint(main_);
  if (::unlink(main_.c_str()) != 0 && errno != ENOENT)
    throw Error(main_ + ": cannot replace the previous output: " + errnoText(errno));
  for (const auto& f : dropped_)
    if (::unlink(f.c_str()) != 0 && errno != ENOENT)
      throw Error(f + ": cannot remove the previous output: " + errnoText(errno));
  bool has_main = false;
  for (int pass = 0; pass < 2; ++pass)  // sidecars first, the main file last
    for (const auto& f : finals_) {
      if ((f == main_) != (pass == 1)) continue;
      has_main = has_main || f == main_;
      const std::string from = (fs::path(staging_) / fs::path(f).filename()).string();
      faultPoint(f);
      if (std::rename(from.c_str(), f.c_str()) != 0)
        throw Error(f + ": cannot publish the output (rename from " + from + "): " + errnoText(errno));
    }
  (void)has_main;
  cancel.armed = false;
  published_ = true;
  cleanup_.release();
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

// ---- fault injection -------------------------------------------------------------

void faultPoint([[maybe_unused]] const std::string& path) {
  [[maybe_unused]] const std::size_t n = ++g_fault_points;
#ifdef EVIO_FAULT_INJECTION
  const FaultPlan& p = faultPlan();
  if (p.after == 0 || n != p.after) return;
  if (p.action < 0) throw Error(path + ": write failed: injected fault (EVIO_FAULT=EIO)");
  ::raise(p.action);
#endif
}

std::size_t faultPointsPassed() { return g_fault_points.load(); }

void writeFaultCount() {
#ifdef EVIO_FAULT_INJECTION
  const char* file = std::getenv("EVIO_FAULT_COUNT_FILE");
  if (!file) return;
  if (std::FILE* f = std::fopen(file, "w")) {
    std::fprintf(f, "%zu\n", g_fault_points.load());
    std::fclose(f);
  }
#endif
}

}  // namespace evio::io
