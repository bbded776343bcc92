#include "evio/core/io/staged_folder.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
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
#include "evio/core/io/library_crash_guard.h"

namespace evio::io {

namespace fs = std::filesystem;

namespace {

// ---- the registry of paths to remove on SIGINT/SIGTERM ----------------------
// Fixed storage, lock-free atomics: the handler reads it without allocating.
// A slot's path is read by the handler only after the handler claimed the
// slot (kActive -> kHandler); a claimed slot is never freed, so no thread
// can rewrite the path while the handler reads it. A thread publishing the
// path claims it first (kActive -> kPublishing), so the handler never
// empties a folder that is being renamed into place.
constexpr int kSlots = 256;
constexpr std::size_t kPathMax = 4096;
enum SlotState : int { kFree = 0, kWriting = 1, kActive = 2, kHandler = 3, kPublishing = 4 };
struct Slot {
  std::atomic<int> state{kFree};
  bool child_staging = false;  // also remove "<path>.staging.<pid>" of a child process
  std::size_t name_at = 0;     // where the last path component starts
  std::atomic<long> publisher{0};  // thread id of the publishing thread (kPublishing)
  char path[kPathMax];
};
Slot g_slots[kSlots];
std::atomic<bool> g_interrupted{false};  // set first thing by the handler

/// Blocks this thread until the interrupt handler (running on another
/// thread) ends the process.
[[noreturn]] void waitForExit() {
  for (;;) ::pause();
}

bool isDotOrDotDot(const char* n) { return n[0] == '.' && (n[1] == '\0' || (n[1] == '.' && n[2] == '\0')); }

/// Removes `name` (relative to `dirfd`) and everything under it with system
/// calls only (async-signal-safe). Repeats a folder a few times in case
/// another thread was still creating files in it.
void removeTreeAt(int dirfd, const char* name, int depth) {
  if (::unlinkat(dirfd, name, 0) == 0 || errno == ENOENT) return;
  if (depth > 24) return;
  for (int pass = 0; pass < 8; ++pass) {
    const int fd = ::openat(dirfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return;
    alignas(16) char buf[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof(buf));
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        const auto* d = reinterpret_cast<const struct dirent64*>(buf + off);
        off += d->d_reclen;
        if (!isDotOrDotDot(d->d_name)) removeTreeAt(fd, d->d_name, depth + 1);
      }
    }
    ::close(fd);
    if (::unlinkat(dirfd, name, AT_REMOVEDIR) == 0 || errno == ENOENT) return;
  }
}

void writeAll(const char* s) { (void)!::write(2, s, std::strlen(s)); }

/// True when `name` is `base` + ".staging." + digits (a child's staging folder).
bool isChildStaging(const char* name, const char* base, std::size_t base_len) {
  for (std::size_t i = 0; i < base_len; ++i)
    if (name[i] != base[i]) return false;
  const char* marker = ".staging.";
  std::size_t i = base_len;
  for (std::size_t k = 0; marker[k] != '\0'; ++k, ++i)
    if (name[i] != marker[k]) return false;
  if (name[i] == '\0') return false;
  for (; name[i] != '\0'; ++i)
    if (name[i] < '0' || name[i] > '9') return false;
  return true;
}

/// The pid at the end of a child's staging name "<base>.staging.<pid>".
pid_t stagingPid(const char* name, std::size_t base_len) {
  pid_t pid = 0;
  for (const char* c = name + base_len + std::strlen(".staging."); *c != '\0'; ++c) pid = pid * 10 + (*c - '0');
  return pid;
}

/// Stops the child that writes a staging folder before the folder goes:
/// a child still running can create a file in it while it is being removed
/// and leave it behind (the fault suite saw imu.txt.tmp.* left so under
/// load). Only a running child of this process is stopped (waitpid says
/// so: a pid that is not our child, or one already reaped, is left alone).
/// System calls only.
void stopChild(pid_t pid) {
  int status = 0;
  if (pid <= 0 || ::waitpid(pid, &status, WNOHANG) != 0) return;
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
}

/// Removes the "<path>.staging.<pid>" folders beside `slot.path`, each after
/// stopping its child (system calls only).
void removeChildStaging(const Slot& slot) {
  char dir[kPathMax];
  const std::size_t n = slot.name_at;
  if (n == 0) {
    dir[0] = '.', dir[1] = '\0';
  } else {
    for (std::size_t i = 0; i < n; ++i) dir[i] = slot.path[i];
    dir[n] = '\0';
  }
  const char* base = slot.path + slot.name_at;
  const std::size_t base_len = std::strlen(base);
  const int fd = ::open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  alignas(16) char buf[4096];
  for (;;) {
    const long got = ::syscall(SYS_getdents64, fd, buf, sizeof(buf));
    if (got <= 0) break;
    for (long off = 0; off < got;) {
      const auto* d = reinterpret_cast<const struct dirent64*>(buf + off);
      off += d->d_reclen;
      if (!isChildStaging(d->d_name, base, base_len)) continue;
      stopChild(stagingPid(d->d_name, base_len));
      removeTreeAt(fd, d->d_name, 0);
    }
  }
  ::close(fd);
}

long threadId() { return ::syscall(SYS_gettid); }

/// Removes every registered path this thread may remove (system calls only).
void removeRegisteredPaths() {
  const long self = threadId();
  for (auto& slot : g_slots) {
    int expected = kActive;
    if (!slot.state.compare_exchange_strong(expected, kHandler)) {
      // Being published by another thread: leave it (the next run removes a
      // leftover). Published by this very thread, the rename is not running.
      expected = kPublishing;
      if (slot.publisher.load() != self || !slot.state.compare_exchange_strong(expected, kHandler)) continue;
    }
    removeTreeAt(AT_FDCWD, slot.path, 0);
    if (slot.child_staging) removeChildStaging(slot);
  }
}

extern "C" void onInterrupt(int sig) {
  g_interrupted.store(true);
  removeRegisteredPaths();
  writeAll(sig == SIGINT ? "evio: interrupted (SIGINT); unfinished output removed\n"
                         : "evio: terminated (SIGTERM); unfinished output removed\n");
  ::_exit(128 + sig);
}

// The file a third-party library is reading on this thread (LibraryCrashGuard).
thread_local const char* t_crash_library = nullptr;
thread_local const char* t_crash_file = nullptr;

extern "C" void onLibraryCrash(int sig) {
  if (t_crash_file == nullptr) {  // not inside a guarded read: the default action
    ::signal(sig, SIG_DFL);
    return;  // the faulting instruction runs again and takes it
  }
  g_interrupted.store(true);
  removeRegisteredPaths();
  writeAll("evio: error: ");
  writeAll(t_crash_file);
  writeAll(": the ");
  writeAll(t_crash_library);
  writeAll(" library crashed reading this file (");
  writeAll(sig == SIGFPE ? "SIGFPE" : sig == SIGBUS ? "SIGBUS" : "SIGSEGV");
  writeAll("); corrupt or hostile file, nothing published\n");
  ::_exit(1);
}

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

// ---- interruption -----------------------------------------------------------

void installInterruptHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGINT);
  sigaddset(&sa.sa_mask, SIGTERM);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  std::signal(SIGXFSZ, SIG_IGN);  // a file-size limit fails the write (EFBIG) instead of killing
#if !defined(__SANITIZE_ADDRESS__)  // under ASan (debug preset) its own report is worth more
  struct sigaction crash {};
  crash.sa_handler = onLibraryCrash;
  sigemptyset(&crash.sa_mask);
  crash.sa_flags = SA_NODEFER;  // SIG_DFL is re-armed inside, and the fault repeats on return
  for (const int sig : {SIGFPE, SIGSEGV, SIGBUS}) ::sigaction(sig, &crash, nullptr);
#endif
}

LibraryCrashGuard::LibraryCrashGuard(const char* library, const std::string& file)
    : previous_library_(t_crash_library), previous_file_(t_crash_file), file_(file) {
  t_crash_library = library;
  t_crash_file = file_.c_str();
}

LibraryCrashGuard::~LibraryCrashGuard() {
  t_crash_file = previous_file_;
  t_crash_library = previous_library_;
}

InterruptCleanup::InterruptCleanup(const std::string& path, Scope scope) {
  if (path.size() + 1 > kPathMax) return;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (g_slots[i].state.compare_exchange_strong(expected, kWriting)) {
      Slot& slot = g_slots[i];
      std::memcpy(slot.path, path.c_str(), path.size() + 1);
      const std::size_t slash = path.rfind('/');
      slot.name_at = slash == std::string::npos ? 0 : slash + 1;
      slot.child_staging = scope == Scope::kWithChildStaging;
      slot.state.store(kActive);
      slot_ = i;
      // The handler is already running on another thread and may have passed
      // this slot: create nothing more, the process is about to end.
      if (g_interrupted.load()) waitForExit();
      return;
    }
  }
}

void InterruptCleanup::confirmCreated() const {
  if (slot_ < 0 || !g_interrupted.load()) return;
  // The handler may have looked before the path existed: remove it here.
  removeTreeAt(AT_FDCWD, g_slots[slot_].path, 0);
  waitForExit();
}

void InterruptCleanup::beginPublish() {
  if (slot_ < 0) return;
  g_slots[slot_].publisher.store(threadId());
  int expected = kActive;
  if (g_slots[slot_].state.compare_exchange_strong(expected, kPublishing)) return;
  if (expected == kHandler) waitForExit();  // being removed: never publish it
}

void InterruptCleanup::cancelPublish() {
  if (slot_ < 0) return;
  int expected = kPublishing;
  g_slots[slot_].state.compare_exchange_strong(expected, kActive);
}

InterruptCleanup::~InterruptCleanup() { release(); }

InterruptCleanup::InterruptCleanup(InterruptCleanup&& other) noexcept : slot_(other.slot_) { other.slot_ = -1; }

InterruptCleanup& InterruptCleanup::operator=(InterruptCleanup&& other) noexcept {
  if (this != &other) {
    release();
    slot_ = other.slot_;
    other.slot_ = -1;
  }
  return *this;
}

void InterruptCleanup::release() {
  if (slot_ < 0) return;
  // Free the slot unless the handler claimed it (it then stays claimed until
  // the process ends, so its path is never rewritten under the handler).
  for (int from : {kActive, kPublishing}) {
    int expected = from;
    if (g_slots[slot_].state.compare_exchange_strong(expected, kFree)) break;
  }
  slot_ = -1;
}

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
