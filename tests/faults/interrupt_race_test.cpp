// The SIGINT/SIGTERM handler of core/io/staged_folder.h while other threads
// keep writing and publishing (issue 19: "a slot reused while the handler
// reads it"). A forked process runs worker threads that each publish a
// StagedFolder of kFiles files again and again into its own target; its main
// thread raises SIGTERM after a seeded delay, so the handler runs on one
// thread while the workers register, create, publish and release on others.
// After every run: the process ended with 143 (no hang), every published
// target holds all its files (the handler never empties a folder that is
// being renamed into place), and every leftover is a staging name that the
// next run removes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "evio/core/io/staged_folder.h"

namespace evio::io {
namespace {

namespace fs = std::filesystem;
constexpr int kWorkers = 4;
constexpr int kRuns = 150;
constexpr int kFiles = 20;

/// The forked process: workers publish until the signal ends the process.
/// prefix + n, built by appending: GCC 12 at -O3 gives a false -Wrestrict
/// (an error under CI's -Werror) on "literal" + std::to_string(n).
std::string numbered(const char* prefix, long n) {
  std::string s = prefix;
  s += std::to_string(n);
  return s;
}

[[noreturn]] void runWorkersUntilSignal(const fs::path& dir, int delay_us) {
  installInterruptHandlers();
  std::vector<std::thread> workers;
  for (int w = 0; w < kWorkers; ++w)
    workers.emplace_back([dir, w] {
      const std::string target = (dir / numbered("w", w)).string();
      for (;;) {
        try {
          StagedFolder out(target);
          for (int f = 0; f < kFiles; ++f) {
            const std::string file = out.path() + numbered("/f", f);
            if (std::FILE* fp = std::fopen(file.c_str(), "w")) std::fclose(fp);
          }
          out.publish();
        } catch (...) {
          // A folder removed under us by the handler: the process ends anyway.
        }
      }
    });
  std::this_thread::sleep_for(std::chrono::microseconds(delay_us));
  std::raise(SIGTERM);  // the handler runs on this thread, the workers go on
  for (;;) ::pause();
}

/// Exit code of `pid`, or -1 when it has not ended within `limit_s` (then killed).
int waitWithLimit(pid_t pid, double limit_s) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid)
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limit_s) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::size_t filesIn(const fs::path& p) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(p)) ++n;
  return n;
}

TEST(InterruptRace, PublishedOutputsStayWholeAndLeftoversAreStaleStaging) {
  const fs::path dir = fs::temp_directory_path() / numbered("evio_race_", ::getpid());
  std::mt19937 rng(19);  // seeded delays: the same schedule every run
  std::uniform_int_distribution<int> delay_us(200, 20000);
  int runs_with_leftovers = 0;
  for (int run = 0; run < kRuns; ++run) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    const int delay = delay_us(rng);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) runWorkersUntilSignal(dir, delay);
    ASSERT_EQ(waitWithLimit(pid, 20.0), 143) << "run " << run << " (delay " << delay << " us): no clean SIGTERM exit";
    bool leftover = false;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      if (isStagingName(name)) {
        leftover = true;
        continue;
      }
      EXPECT_EQ(filesIn(e.path()), static_cast<std::size_t>(kFiles))
          << "run " << run << ": published " << name << " was emptied while being published";
    }
    runs_with_leftovers += leftover;
    for (int w = 0; w < kWorkers; ++w) {
      removeStaleStaging((dir / numbered("w", w)).string());
    }
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_FALSE(isStagingName(e.path().filename().string())) << "run " << run << ": not removed: " << e.path();
  }
  fs::remove_all(dir);
  std::printf("interrupt race: %d runs, %d left a staging folder that the next run removed\n", kRuns, runs_with_leftovers);
}

}  // namespace
}  // namespace evio::io
