#pragma once
/// @file library_crash_guard.h
/// A crash inside a third-party reader on a hostile file is one evio error.
///
/// libhdf5 (1.10.8, Debian 12) has memory errors of its own on crafted
/// files, found by tests/fuzz/fuzz_events_h5.cpp: e.g. a chunk dimension of 0
/// in a dataset's layout message divides by zero inside H5Dopen2
/// (H5D__chunk_set_info, SIGFPE). evio cannot repair the library, so while a
/// LibraryCrashGuard lives, a SIGFPE, SIGSEGV or SIGBUS on its thread ends
/// the process with one line, "evio: error: <file>: the <library> library
/// crashed reading this file (<signal>); corrupt or hostile file, nothing
/// published", after removing every staging folder and temporary file
/// registered with InterruptCleanup (core/io/staged_folder.h), and exit
/// code 1. The handlers are installed by installInterruptHandlers(); outside
/// a guard these signals keep their default action (a crash of evio itself
/// stays a crash, with its core dump). AddressSanitizer builds keep ASan's
/// own handlers (its report names the fault) and do not install these.

#include <string>

namespace evio::io {

class LibraryCrashGuard {
 public:
  /// `library` must outlive the guard (a string literal); `file` is copied.
  LibraryCrashGuard(const char* library, const std::string& file);
  ~LibraryCrashGuard();
  LibraryCrashGuard(const LibraryCrashGuard&) = delete;
  LibraryCrashGuard& operator=(const LibraryCrashGuard&) = delete;

 private:
  const char* previous_library_;
  const char* previous_file_;
  std::string file_;
};

}  // namespace evio::io
