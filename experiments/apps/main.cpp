// The `evio` command-line tool: one executable, one subcommand per job.
// Errors are printed as one line on stderr with a non-zero exit code
// (README: exit codes): 0 done, 1 error (nothing published), 2 internal
// error, 3 ran but the result failed, 100-199 usage, 130/143 interrupted.
#include <cstdio>
#include <exception>
#include <filesystem>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/staged_folder.h"
#include "evio/core/version.h"

namespace {

/// glibc's allocator serves blocks above its mmap threshold (128 KiB at
/// first, then the largest block freed) from fresh mappings and returns the
/// heap's free top to the kernel above its trim threshold, so per-frame
/// buffers (OpenCV's Harris and pyramid images, a few hundred KiB each)
/// came back as new zeroed pages on every frame: 40 700 page faults and
/// 0.14-0.18 s of system time in a 12 s EKLT-VIO run of poster_6dof, 5 %
/// of its CPU. Blocks up to 16 MiB now come from the heap and up to 64 MiB
/// of free top is kept: 6 400 faults, 0.03 s, peak memory +2 MB (README,
/// "Real time").
void keepFreedMemoryMapped() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 16 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
#endif
}

int finish(int code) {
  evio::io::writeFaultCount();
  return code;
}
}  // namespace

int main(int argc, char** argv) {
  keepFreedMemoryMapped();
  evio::io::installInterruptHandlers();
  CLI::App app{"evio: event-camera visual-inertial odometry test bench (simulate, estimate, evaluate)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", evio::evioVersion());
  evio::apps::addAllCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return finish(app.exit(e));
  } catch (const evio::Error& e) {
    std::fprintf(stderr, "evio: error: %s\n", e.what());
    return finish(1);
  } catch (const std::filesystem::filesystem_error& e) {
    // A path of the wrong kind, a symlink loop, a permission: name the path.
    const std::string where = !e.path1().empty() ? e.path1().string() : "filesystem";
    std::fprintf(stderr, "evio: error: %s: %s\n", where.c_str(), e.code().message().c_str());
    return finish(1);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "evio: error: out of memory\n");
    return finish(1);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evio: internal error: %s\n", e.what());
    return finish(2);
  }
  return finish(evio::apps::exitCode());
}
