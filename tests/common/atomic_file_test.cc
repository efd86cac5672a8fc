// Files written whole or not at all, and the clean-up of what a killed writer leaves.

#include "common/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "common/csv.h"
#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

using testing::fresh_scratch_dir;

int files_in(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}

TEST(AtomicFile, WritesAndReplacesLeavingNoTemporary) {
  const std::string dir = fresh_scratch_dir("write");
  write_file_atomically(dir + "/a.json", "first");
  EXPECT_EQ(read_text_file(dir + "/a.json"), "first");
  write_file_atomically(dir + "/a.json", std::string(100000, 'x'));
  EXPECT_EQ(read_text_file(dir + "/a.json"), std::string(100000, 'x'));
  write_file_atomically(dir + "/empty", "");
  EXPECT_EQ(read_text_file(dir + "/empty"), "");
  EXPECT_EQ(files_in(dir), 2);
}

TEST(AtomicFile, ConcurrentWritersOfOnePathLeaveOneWholeVersion) {
  // Eight threads write their own 64 kB text to one path many times: whatever is read after is
  // exactly one of the texts, never a mix.
  const std::string dir = fresh_scratch_dir("race");
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      for (int k = 0; k < 20; ++k) {
        write_file_atomically(dir + "/x", std::string(65536, static_cast<char>('a' + t)));
      }
    });
  }
  for (std::thread& t : threads) t.join();
  const std::string text = read_text_file(dir + "/x");
  ASSERT_EQ(text.size(), 65536u);
  EXPECT_EQ(text, std::string(65536, text[0]));
  EXPECT_EQ(files_in(dir), 1);
}

TEST(AtomicFile, MissingFolderIsAnInputErrorNamingThePath) {
  const std::string dir = fresh_scratch_dir("missing");
  try {
    write_file_atomically(dir + "/no/such/a.json", "x");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.json"), std::string::npos) << e.what();
  }
  EXPECT_EQ(files_in(dir), 0);
}

TEST(AtomicFile, StaleTemporariesAreRemovedAndNothingElse) {
  // What a writer killed between write and rename leaves: "<target>.tmp.<pid>.<n>".
  const std::string dir = fresh_scratch_dir("stale");
  fs::create_directories(dir + "/runs/line");
  std::ofstream(dir + "/runs/line/seed-1.json.tmp.123.0") << "{\"scen";
  std::ofstream(dir + "/runs/line/seed-2.json") << "{}";
  std::ofstream(dir + "/keep.txt") << "x";
  EXPECT_EQ(remove_stale_temp_files(dir), 1);
  EXPECT_FALSE(fs::exists(dir + "/runs/line/seed-1.json.tmp.123.0"));
  EXPECT_TRUE(fs::exists(dir + "/runs/line/seed-2.json"));
  EXPECT_TRUE(fs::exists(dir + "/keep.txt"));
  EXPECT_EQ(remove_stale_temp_files(dir + "/none"), 0);
}

}  // namespace
}  // namespace airtwin
