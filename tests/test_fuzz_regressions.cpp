// SPDX-License-Identifier: MIT
// Replays the fuzz targets (fuzz/fuzz_*.cpp, compiled into this program without libFuzzer; see
// fuzz/fuzz_target.h) on their seed corpus (fuzz/corpus/<target>/) and on every input a fuzzer found a
// crash, hang or leak with (tests/fuzz_regressions/<target>/, kept after the reader was fixed): each input
// must read successfully or throw trivcon::Error, nothing else (scripts/test.sh --sanitize runs this under
// ASan + UBSan too). New files in those folders are picked up without rebuilding.
#include <gtest/gtest.h>

#include "support.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_target.h"

namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = TRIVCON_FUZZ_CORPUS;
const fs::path kRegressions = TRIVCON_FUZZ_REGRESSIONS;

std::vector<std::string> target_names() {
  std::vector<std::string> names;
  for (const auto& [name, target] : trivcon::fuzz::targets()) names.push_back(name);
  return names;
}

// The regular files of `dir` (none when it does not exist), sorted.
std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Runs the target on the file: "" when it read or threw trivcon::Error ("error" in *threw), else what went wrong.
std::string replay(trivcon::fuzz::Target target, const fs::path& file, bool* threw) {
  *threw = false;
  try {
    target(trivcon::test::slurp(file.string()));
    return "";
  } catch (const trivcon::Error&) {
    *threw = true;
    return "";
  } catch (const std::exception& e) {
    return file.string() + ": not a trivcon::Error: " + e.what();
  } catch (...) {
    return file.string() + ": threw something that is not a std::exception";
  }
}

class FuzzReplay : public testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, SeedsReadOrThrowTrivconError) {
  const std::vector<fs::path> seeds = files_in(kCorpus / GetParam());
  ASSERT_FALSE(seeds.empty()) << "no seeds in " << kCorpus / GetParam();
  int read = 0;
  std::uintmax_t total = 0;
  for (const fs::path& seed : seeds) {
    bool threw;
    EXPECT_EQ(replay(trivcon::fuzz::targets().at(GetParam()), seed, &threw), "");
    read += !threw;
    total += fs::file_size(seed);
  }
  std::printf("%d of %zu seeds of %s read without an error\n", read, seeds.size(), GetParam().c_str());
  EXPECT_GT(read, 0) << "not one seed of " << GetParam() << " reads: the corpus should hold valid files too";
  EXPECT_LE(total, 16u * 1024) << "the seed corpus of " << GetParam() << " should stay small";
}

TEST_P(FuzzReplay, RegressionsReadOrThrowTrivconError) {
  for (const fs::path& input : files_in(kRegressions / GetParam())) {
    bool threw;
    EXPECT_EQ(replay(trivcon::fuzz::targets().at(GetParam()), input, &threw), "");
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, testing::ValuesIn(target_names()),
                         [](const testing::TestParamInfo<std::string>& info) { return info.param; });

// A folder named after no target would never be replayed (a typo, or a target renamed).
TEST(FuzzReplay, EveryFolderNamesATarget) {
  EXPECT_GE(trivcon::fuzz::targets().size(), 12u);
  for (const fs::path& root : {kCorpus, kRegressions}) {
    if (!fs::is_directory(root)) continue;
    for (const fs::directory_entry& entry : fs::directory_iterator(root)) {
      if (!entry.is_directory()) continue;
      EXPECT_EQ(trivcon::fuzz::targets().count(entry.path().filename().string()), 1u) << entry.path() << " names no fuzz target";
    }
  }
}

}  // namespace
