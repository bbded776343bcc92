// Outputs as transactions (core/io/staged_folder.h) and the bounds on hostile
// text input (line length, seconds that overflow int64 nanoseconds).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/staged_folder.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("evio_staged_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

TEST(StagedFolder, PublishReplacesTheTargetWhole) {
  const fs::path dir = scratch("replace");
  const std::string target = (dir / "out").string();
  fs::create_directories(target);
  writeFileAtomic(target + "/old_only.txt", "old");
  writeFileAtomic(target + "/both.txt", "old");
  {
    StagedFolder out(target);
    EXPECT_TRUE(isStagingName(out.path()));
    writeFileAtomic(out.path() + "/both.txt", "new");
    EXPECT_EQ(readFile(target + "/both.txt"), "old");  // nothing visible before publish
    out.publish();
  }
  EXPECT_EQ(readFile(target + "/both.txt"), "new");
  EXPECT_FALSE(fs::exists(target + "/old_only.txt"));  // no mix of the two runs
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(StagedFolder, UnpublishedLeavesNothingAndTheOldOutputStays) {
  const fs::path dir = scratch("abandon");
  const std::string target = (dir / "out").string();
  fs::create_directories(target);
  writeFileAtomic(target + "/a.txt", "old");
  { StagedFolder out(target); writeFileAtomic(out.path() + "/a.txt", "new"); }
  EXPECT_EQ(readFile(target + "/a.txt"), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(StagedFolder, StaleStagingOfADeadProcessIsRemovedAndAHalfPublishedOldRestored) {
  const fs::path dir = scratch("stale");
  const std::string target = (dir / "out").string();
  const pid_t child = ::fork();  // a PID of this system whose process has ended
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child);
  fs::create_directories(target + ".staging." + dead);
  fs::create_directories(target + ".old." + dead);
  writeFileAtomic(target + ".old." + dead + "/a.txt", "previous");
  // Not ours: a number no PID can have (a user's dated backup), and names of other shapes.
  fs::create_directories(target + ".old.20240101999");
  writeFileAtomic(target + ".tmp.123", "a user's file");
  EXPECT_EQ(removeStaleStaging(target), 2u);
  EXPECT_FALSE(fs::exists(target + ".staging." + dead));
  EXPECT_EQ(readFile(target + "/a.txt"), "previous");
  EXPECT_TRUE(fs::exists(target + ".old.20240101999"));
  EXPECT_TRUE(fs::exists(target + ".tmp.123"));
  fs::remove_all(dir);
}

TEST(StagedFolder, ASymbolicLinkAsTheOutputFolderIsRefusedUpFront) {
  const fs::path dir = scratch("link");
  fs::create_directories(dir / "real");
  fs::create_directory_symlink(dir / "real", dir / "link");
  EXPECT_THROW(checkOutputFolder((dir / "link").string()), Error);
  EXPECT_NO_THROW(checkOutputFolder((dir / "real").string()));
  fs::remove_all(dir);
}

TEST(StagedFolder, ConsumersRefuseStagingNames) {
  EXPECT_TRUE(isStagingName("a/seq.staging.123"));
  EXPECT_TRUE(isStagingName("a/seq.staging.123/"));
  EXPECT_TRUE(isStagingName("a/seq.old.7"));
  EXPECT_TRUE(isStagingName("a/trajectory.txt.tmp.12.3"));
  EXPECT_TRUE(isStagingName("cache/seq.tmp.host.12.3"));
  EXPECT_FALSE(isStagingName("a/seq"));
  EXPECT_FALSE(isStagingName("a/staging.1"));
  EXPECT_FALSE(isStagingName("a/seq.staging.x1"));
  EXPECT_THROW(requireNotStaging("seq.staging.1"), Error);
}

TEST(StagedFolder, OutputUnderAFileOrOntoAFileIsOneErrorNamingThePath) {
  const fs::path dir = scratch("kind");
  writeFileAtomic((dir / "f").string(), "x");
  try {
    StagedFolder out((dir / "f" / "out").string());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "f").string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(StagedFolder((dir / "f").string()), Error);
  EXPECT_THROW(readFile(dir.string()), Error);
  EXPECT_THROW(config::loadFile(dir.string()), Error);
  fs::remove_all(dir);
}

TEST(StagedFiles, MainFilePublishedLastWithItsOwnSidecars) {
  const fs::path dir = scratch("files");
  const std::string main = (dir / "m.json").string();
  writeFileAtomic(main, "old");
  writeFileAtomic((dir / "m_rtf.csv").string(), "old");
  {
    StagedFiles s(main);
    writeFileAtomic(s.path((dir / "m_poses.csv").string()), "new");
    writeFileAtomic(s.path(main), "new");
    s.drop((dir / "m_rtf.csv").string());
    s.publish();
  }
  EXPECT_EQ(readFile(main), "new");
  EXPECT_EQ(readFile((dir / "m_poses.csv").string()), "new");
  EXPECT_FALSE(fs::exists(dir / "m_rtf.csv"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);
  fs::remove_all(dir);
}

TEST(AtomicFile, AFailedRenameLeavesNoTemporary) {
  const fs::path dir = scratch("rename");
  fs::create_directories(dir / "target_is_a_folder" / "x");
  EXPECT_THROW(writeFileAtomic((dir / "target_is_a_folder").string(), "data"), Error);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(HostileInput, SecondsThatOverflowInt64NanosecondsAreRejected) {
  TimeNs t = 0;
  EXPECT_TRUE(parseSecondsToNs("9223372036.854775807", &t));
  EXPECT_EQ(t, 9223372036854775807LL);
  EXPECT_FALSE(parseSecondsToNs("9223372036.854775808", &t));
  EXPECT_FALSE(parseSecondsToNs("9223372036.9", &t));
  EXPECT_FALSE(parseSecondsToNs("9223372037", &t));
  EXPECT_FALSE(parseSecondsToNs("-9223372037.5", &t));
  EXPECT_TRUE(parseSecondsToNs("1700000000.123456789", &t));
  EXPECT_EQ(t, 1700000000123456789LL);
}

TEST(HostileInput, ALineLongerThanTheBoundIsAnErrorNamingFileAndLine) {
  const fs::path dir = scratch("line");
  const std::string path = (dir / "long.txt").string();
  {
    std::ofstream f(path);
    f << "1 2 3\n" << std::string(LineReader::kMaxLineBytes + 10, '7');
  }
  LineReader r(path);
  std::string_view line;
  ASSERT_TRUE(r.next(line));
  try {
    r.next(line);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("long.txt:2: line longer than"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace evio::io
