// `bimart data stats` through its CLI11 sub-command, in-process (the `data` command that
// hosts it lives in core/cli/data_commands.cc).
#include "core/cli/data_stats_command.h"

#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/metrics/hand_vertices.h"
#include "core/util/data_path.h"

#include <filesystem>

#include "core/data/normalization.h"
#include "tests/data/tiny_dataset.h"

namespace bimart {
namespace {

using testing_data::tiny_dataset;
namespace fs = std::filesystem;

// Parses `args` as `bimart data <args>` and runs the chosen command; returns its exit code.
int run_data(const std::string& args, std::string* output) {
  CLI::App app{"test", "bimart"};
  CLI::App* data = app.add_subcommand("data", "data sets");
  data->require_subcommand(1);
  cli::Commands commands;
  cli::add_data_stats_command(*data, commands);
  app.parse("data " + args, false);
  ::testing::internal::CaptureStdout();
  int status = -1;
  for (const cli::Command& c : commands)
    if (c.app->parsed()) {
      EXPECT_FALSE(c.needs_plugins);
      status = c.run();
    }
  *output = ::testing::internal::GetCapturedStdout();
  return status;
}

TEST(DataStatsCli, WritesTheNormalisationFile) {
  const fs::path dir = tiny_dataset().dir;
  const fs::path out = dir / "cli" / "stats.npz";
  std::string text;
  ASSERT_EQ(run_data("stats " + dir.string() + " --out " + out.string() + " --no-cache", &text), 0);
  EXPECT_NE(text.find("sequences  3"), std::string::npos) << text;
  EXPECT_NE(text.find("frames     204"), std::string::npos) << text;
  EXPECT_NE(text.find("windows    6 of 64 frames, stride 16"), std::string::npos) << text;
  EXPECT_NE(text.find("memory"), std::string::npos) << text;
  EXPECT_NE(text.find("wrote " + out.string()), std::string::npos) << text;
  const NormalizationStats s = load_normalization(out.string());
  EXPECT_EQ(s.variant, "np_bps");
  EXPECT_EQ(s.count, 360);

  // Default output in the current folder (not in the data set: eval reads its .npz files),
  // another variant and stride.
  const fs::path cwd = fs::current_path();
  fs::create_directories(dir / "cwd");
  fs::current_path(dir / "cwd");
  const int status = run_data("stats " + dir.string() + " --variant u_bps --stride 32 --no-cache", &text);
  fs::current_path(cwd);
  ASSERT_EQ(status, 0);
  EXPECT_NE(text.find("windows    5 of 64 frames, stride 32"), std::string::npos) << text;  // 0, 32, 36; 0; 0
  EXPECT_EQ(load_normalization((dir / "cwd" / "stats_u_bps.npz").string()).variant, "u_bps");

  // Own hand models (here the shipped files, named explicitly) pose the hands: same numbers.
  const fs::path own = dir / "cli" / "stats_own.npz";
  ASSERT_EQ(run_data("stats " + dir.string() + " --out " + own.string() + " --no-cache --mano-left " +
                         find_data_file("models/hand/mano_left.npz") + " --mano-right " +
                         find_data_file("models/hand/mano_right.npz"),
                     &text),
            0);
  set_posing_hand_models("", "");  // back to the default for the other tests
  const NormalizationStats a = load_normalization(out.string()), b = load_normalization(own.string());
  EXPECT_TRUE(at::equal(a.x_mean, b.x_mean));
  EXPECT_TRUE(at::equal(a.c_std, b.c_std));

  EXPECT_THROW(run_data("stats " + dir.string() + " --variant npbps", &text), CLI::ValidationError);
  EXPECT_THROW(run_data("stats " + (dir / "nowhere").string(), &text), CLI::ValidationError);
}

}  // namespace
}  // namespace bimart
