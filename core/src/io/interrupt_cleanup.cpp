// The interrupt clean-up of staged_folder.h: a fixed registry of paths
// that the SIGINT/SIGTERM handler (and the library-crash handler) removes
// with system calls only, the handlers themselves, and InterruptCleanup,
// which registers, confirms and releases a path. The staged outputs that use
// it are in staged_folder.cpp.
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <string>

#include "evio/core/io/library_crash_guard.h"
#include "evio/core/io/staged_folder.h"

namespace evio::io {

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

}  // namespace evio::io
