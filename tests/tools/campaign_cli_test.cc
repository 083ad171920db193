// stewart_campaign as a user runs it: a campaign folder, the same rows from
// shards run by GNU parallel and merged, one row re-run alone and emitted as
// a truth file, and one clear error for a bad distribution file.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/config/truth_loader.h"
#include "stewart/stack/campaign_summary.h"

namespace stewart {
namespace {

namespace fs = std::filesystem;

int Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every column but the wall time.
void ExpectSameRows(const CsvTable& a, const CsvTable& b) {
  ASSERT_EQ(a.header, b.header);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  const auto wall = static_cast<std::size_t>(a.Column("wall_s"));
  for (std::size_t r = 0; r < a.rows.size(); ++r) {
    for (std::size_t c = 0; c < a.header.size(); ++c) {
      if (c == wall) continue;
      EXPECT_EQ(a.rows[r][c], b.rows[r][c]) << a.header[c] << " row " << r;
    }
  }
}

class CampaignCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir() + "/campaign_cli_" + std::to_string(::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string dir_;
  const std::string bin_ = CAMPAIGN_PATH;
  const std::string common_ = " --runs 4 --duration 1 --scenario random --seed 3 --mismatch " +
                              std::string(STEWART_SOURCE_DIR) + "/config/campaigns/bounds.yaml";
};

TEST_F(CampaignCli, ParallelShardsMergeToTheSameRowsAndARowReruns) {
  const std::string a = dir_ + "/a";
  ASSERT_EQ(
      Shell(bin_ + common_ + " --jobs 2 --no-plots --out " + a + " > " + dir_ + "/a.out 2>&1"), 0)
      << ReadText(dir_ + "/a.out");
  for (const char* file : {"runs.csv", "summary.json", "summary.md", "campaign.json", "config.yaml",
                           "mismatch.yaml"}) {
    EXPECT_TRUE(fs::exists(a + "/" + file)) << file;
  }
  const CsvTable direct = ReadCsv(a + "/runs.csv");
  ASSERT_EQ(direct.rows.size(), 4u);

  const std::string b = dir_ + "/b";
  ASSERT_EQ(Shell("STEWART_BUILD_DIR=" + std::string(STEWART_BUILD_DIR) + " " + STEWART_SOURCE_DIR +
                  "/tools/campaign_parallel.sh " + b + " 3 -j 2 --" + common_ + " > " + dir_ +
                  "/b.out 2>&1"),
            0)
      << ReadText(dir_ + "/b.out");
  ExpectSameRows(direct, ReadCsv(b + "/runs.csv"));
  EXPECT_NE(ReadText(b + "/summary.md").find("4 runs;"), std::string::npos);

  // Row 2 alone: its trajectory, the same row, its truth and launch line.
  const std::string out = dir_ + "/rerun.out";
  ASSERT_EQ(Shell(bin_ + " --rerun " + a + " --row 2 --emit-truth > " + out + " 2>&1"), 0)
      << ReadText(out);
  const std::string text = ReadText(out);
  EXPECT_NE(text.find("identical to its row"), std::string::npos) << text;
  EXPECT_NE(text.find("tools/launch.sh --config"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(a + "/run_2.csv"));
  EXPECT_TRUE(fs::exists(a + "/run_2_truth.yaml"));
  EXPECT_TRUE(fs::exists(a + "/run_2_scenario.yaml"));
  EXPECT_NE(ReadText(a + "/run_2_truth.yaml").find("initial_state"), std::string::npos);
}

// tools/campaign_slurm.sbatch as a job array on the machine's Slurm (skipped
// without a controller that answers; tools/slurm_local.sh sets one up): the
// merged shards hold the rows of a direct run.
TEST_F(CampaignCli, SlurmJobArrayShardsMergeToTheSameRows) {
  if (Shell("sinfo -h > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "no Slurm controller answers (tools/slurm_local.sh starts one)";
  }
  const std::string a = dir_ + "/a", c = dir_ + "/c";
  ASSERT_EQ(Shell(bin_ + common_ + " --jobs 1 --no-plots --out " + a + " > /dev/null 2>&1"), 0);
  const std::string submit =
      "cd " + std::string(STEWART_SOURCE_DIR) + " && STEWART_BUILD_DIR=" + STEWART_BUILD_DIR +
      " sbatch --parsable --wait --array=1-2 --chdir=" + dir_ + " tools/campaign_slurm.sbatch " +
      c + common_ + " > " + dir_ + "/sbatch.out 2>&1";
  ASSERT_EQ(Shell(submit), 0) << ReadText(dir_ + "/sbatch.out");
  ASSERT_EQ(Shell(bin_ + " --merge " + c + "/shard_1 " + c + "/shard_2 --no-plots --out " + c +
                  " > /dev/null 2>&1"),
            0);
  ExpectSameRows(ReadCsv(a + "/runs.csv"), ReadCsv(c + "/runs.csv"));
}

TEST_F(CampaignCli, BadDistributionExitsTwoNamingTheKey) {
  const std::string bad = dir_ + "/bad.yaml";
  std::ofstream(bad) << "parameters:\n  - {key: actuators.force_gain, uniform: [1.1, 0.9]}\n";
  const std::string out = dir_ + "/bad.out";
  EXPECT_EQ(
      Shell(bin_ + " --runs 2 --mismatch " + bad + " --out " + dir_ + "/c > " + out + " 2>&1"), 2);
  EXPECT_NE(ReadText(out).find("campaign.parameters[0].uniform"), std::string::npos)
      << ReadText(out);
  EXPECT_EQ(Shell(bin_ + " --runs 2 --shard 3/2 --out " + dir_ + "/d > " + out + " 2>&1"), 2);
  EXPECT_NE(ReadText(out).find("--shard"), std::string::npos) << ReadText(out);
}

// --identify-actuators: each run identifies its plant's P-16P motors first;
// the runs complete on the identified motors, the folder records the flag,
// and a config without DC-motor legs is refused naming the flag.
TEST_F(CampaignCli, IdentifyActuatorsRunsOnTheIdentifiedMotors) {
  const std::string p16p = dir_ + "/p16p.yaml";
  std::ofstream(p16p) << LoadMergedConfigYaml(DefaultConfigPath(), {DcMotorOverlayPath()});
  const std::string out = dir_ + "/ident.out";
  const std::string folder = dir_ + "/ident";
  ASSERT_EQ(Shell(bin_ + " --config " + p16p +
                  " --runs 2 --jobs 2 --duration 5 --scenario paper --no-plots --mismatch " +
                  std::string(STEWART_SOURCE_DIR) +
                  "/config/campaigns/p16p-actuators.yaml --identify-actuators --out " + folder +
                  " > " + out + " 2>&1"),
            0)
      << ReadText(out);
  EXPECT_NE(ReadText(folder + "/campaign.json").find("\"identify_actuators\": true"),
            std::string::npos);
  const CsvTable runs = ReadCsv(folder + "/runs.csv");
  ASSERT_EQ(runs.rows.size(), 2u);
  const auto completed = static_cast<std::size_t>(runs.Column("completed"));
  const auto failure = static_cast<std::size_t>(runs.Column("failure"));
  for (const auto& row : runs.rows) {
    EXPECT_EQ(row[completed], "1");
    EXPECT_EQ(row[failure], "");
  }
  // The emitted truth names the legs' model: given with the base config (a
  // truth overrides the file, not the overlays), it is still this plant.
  ASSERT_EQ(Shell(bin_ + " --rerun " + folder + " --row 1 --emit-truth > " + out + " 2>&1"), 0)
      << ReadText(out);
  EXPECT_EQ(LoadPlantTruth(DefaultStackConfig(), folder + "/run_1_truth.yaml").actuators.kind,
            ActuatorKind::kDcMotor);
  EXPECT_EQ(Shell(bin_ + " --runs 2 --identify-actuators --out " + dir_ + "/e > " + out + " 2>&1"),
            2);
  EXPECT_NE(ReadText(out).find("--identify-actuators"), std::string::npos) << ReadText(out);
}

}  // namespace
}  // namespace stewart
