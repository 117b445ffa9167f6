// One CLI convention (docs/cli.md): exit codes 0/1/2/130; -q/-v/--threads/--seed the same
// on every command; outputs checked before any work; no partial outputs.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <chrono>
#include <cstdlib>

#include "tests/cli/run_bimart.h"
#include "tests/robust/fixture.h"

namespace bimart {
namespace {

using test::run_bimart;
using test::ScratchDir;
namespace fs = std::filesystem;

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

// bimart with these arguments, started in `folder`.
test::CliRun run_in(const std::string& folder, const std::string& args) {
  const std::string cmd = "cd '" + folder + "' && " + std::string(BIMART_CLI) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  return {pclose(p), out};
}

TEST(CliConventions, ThreadsAreCappedTheSameGloballyAndPerCommand) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto global = run_bimart("--threads 100000 info");  // ran for minutes
  const auto sub = run_bimart("eval --threads 100000 nowhere");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(exit_code(global.status), 1) << global.output;
  EXPECT_EQ(exit_code(sub.status), 1) << sub.output;
  for (const auto* r : {&global, &sub}) EXPECT_NE(r->output.find("--threads: Value 100000 not in range 0 to"), std::string::npos) << r->output;
  EXPECT_LT(seconds, 30.0);
  const auto negative = run_bimart("--threads -1 info");
  EXPECT_EQ(exit_code(negative.status), 1);
  EXPECT_LT(negative.output.size(), 300u) << negative.output;  // printed a 300-digit range
  EXPECT_EQ(exit_code(run_bimart("--threads 2 info").status), 0);
  EXPECT_EQ(exit_code(run_bimart("info --threads 2").status), 0);
}

TEST(CliConventions, SeedIsANonNegative64BitNumber) {
  ScratchDir dir("seed");
  for (const char* bad : {"-1", "1e23", "18446744073709551616", "3.5", "x"}) {
    const auto r = run_bimart(std::string("object make --category box --out ") + (dir / "o") + " --seed " + bad);
    EXPECT_EQ(exit_code(r.status), 1) << bad << ": " << r.output;  // -1 wrapped to 2^64-1, 1e23 clamped
    EXPECT_NE(r.output.find("seed must be a whole number from 0 to 18446744073709551615"), std::string::npos)
        << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "o"));
  const auto max = run_bimart("object make --category box --out " + (dir / "o") + " --seed 18446744073709551615");
  EXPECT_EQ(exit_code(max.status), 0) << max.output;
  const auto pipeline = run_bimart("graph " + std::string(BIMART_SOURCE_DIR) + "/pipelines/smoke.yaml --seed -1");
  EXPECT_EQ(exit_code(pipeline.status), 1) << pipeline.output;
}

TEST(CliConventions, UserErrorsExitWithOne) {
  const auto unknown = run_bimart("frobnicate");
  EXPECT_EQ(exit_code(unknown.status), 1) << unknown.output;
  EXPECT_NE(unknown.output.find("unknown command 'frobnicate'"), std::string::npos) << unknown.output;
  const auto unknown_sub = run_bimart("object mak");
  EXPECT_EQ(exit_code(unknown_sub.status), 1) << unknown_sub.output;
  EXPECT_NE(unknown_sub.output.find("unknown command 'mak' (did you mean 'make'?)"), std::string::npos)
      << unknown_sub.output;
  // Were 105, 106, 109.
  EXPECT_EQ(exit_code(run_bimart("object make --category box").status), 1);  // required option missing
  EXPECT_EQ(exit_code(run_bimart("object list --bogus").status), 1);
  EXPECT_EQ(exit_code(run_bimart("bench blas --size -3").status), 1);
  EXPECT_EQ(exit_code(run_bimart("--help").status), 0);
  EXPECT_EQ(exit_code(run_bimart("eval --help").status), 0);
}

TEST(CliConventions, QuietAndVerboseWorkOnEveryCommand) {
  ScratchDir dir("quiet");
  test::write_box(dir);
  write_sequence(test::hover_sequence("a"), dir / "gen/a.npz");
  for (const std::string& q : {"-q eval ", "eval -q ", "eval --quiet "}) {
    const auto r = run_bimart(q + (dir / "gen") + " --threads 1");
    EXPECT_EQ(exit_code(r.status), 0) << q << r.output;
    EXPECT_EQ(r.output.find("generated: 1/1"), std::string::npos) << q << r.output;  // no progress lines
  }
  const auto loud = run_bimart("eval " + (dir / "gen") + " --threads 1");
  EXPECT_NE(loud.output.find("generated: 1/1"), std::string::npos) << loud.output;
  EXPECT_EQ(exit_code(run_bimart("object list -v").status), 0);
  EXPECT_EQ(exit_code(run_bimart("-v object list").status), 0);
}

TEST(CliConventions, OutputsAreCheckedBeforeAnyWork) {
  ScratchDir dir("outputs");
  test::write_text(dir / "file", "x");  // a file where a folder should be
  const std::string blocked = dir / "file/sub";
  const auto t0 = std::chrono::steady_clock::now();
  const auto synth = run_bimart("data synth --out " + blocked + " --categories box --train-objects 1 --test-objects 0");
  EXPECT_EQ(exit_code(synth.status), 1) << synth.output;  // was exit 2 "filesystem error"
  EXPECT_NE(synth.output.find("cannot write " + blocked), std::string::npos) << synth.output;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 20.0);

  test::write_box(dir);
  write_sequence(test::hover_sequence("a"), dir / "gen/a.npz");
  const auto refine = run_bimart("refine " + (dir / "gen") + " --threads 1 --out " + blocked);
  EXPECT_EQ(exit_code(refine.status), 1) << refine.output;
  EXPECT_NE(refine.output.find("cannot write " + blocked + "/fit"), std::string::npos) << refine.output;
  EXPECT_EQ(refine.output.find("refining"), std::string::npos) << refine.output;  // before the work

  const auto json = run_bimart("eval " + (dir / "gen") + " --threads 1 --json " + blocked + "/e.json");
  EXPECT_EQ(exit_code(json.status), 1) << json.output;
  EXPECT_EQ(json.output.find(".tmp-"), std::string::npos) << json.output;

  // hand make --picture to a bad path wrote the npz files first.
  const auto hand = run_bimart("hand make --out " + (dir / "hand") + " --picture " + blocked + "/h.png");
  EXPECT_EQ(exit_code(hand.status), 1) << hand.output;
  EXPECT_NE(hand.output.find("cannot write " + blocked + "/h.png"), std::string::npos) << hand.output;
  EXPECT_FALSE(fs::exists(dir / "hand/mano_right.npz"));
  EXPECT_FALSE(fs::exists(dir / "hand/mano_left.npz"));
}

TEST(CliConventions, BpsMakeRefusesToOverwriteWithoutForce) {
  ScratchDir dir("bps");
  const std::string file = dir / "basis.npz";
  ASSERT_EQ(exit_code(run_bimart("bps make --out " + file).status), 0);
  const auto again = run_bimart("bps make --out " + file + " --seed 5");
  EXPECT_EQ(exit_code(again.status), 1) << again.output;
  EXPECT_NE(again.output.find(file + " exists"), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("--force"), std::string::npos) << again.output;
  EXPECT_EQ(exit_code(run_bimart("bps make --out " + file + " --seed 5 --force").status), 0);
  // Run where the default --out (models/bps/np_bps_512.npz, relative) exists, as from the
  // repository root: the shipped basis was overwritten silently.
  test::write_text(dir / "root/models/bps/np_bps_512.npz", "shipped");
  const auto shipped = run_in(dir / "root", "bps make");
  EXPECT_EQ(exit_code(shipped.status), 1) << shipped.output;
  EXPECT_NE(shipped.output.find("models/bps/np_bps_512.npz exists"), std::string::npos) << shipped.output;
  std::ifstream in(dir / "root/models/bps/np_bps_512.npz");
  std::string kept;
  in >> kept;
  EXPECT_EQ(kept, "shipped");
}

TEST(CliConventions, InterruptedExitsWith130) {
  const std::string cmd = "timeout --preserve-status -s INT 5 " + std::string(BIMART_CLI) +
                          " bench blas --size 1024 --repeats 1000000 > /dev/null 2>&1";
  EXPECT_EQ(exit_code(std::system(cmd.c_str())), 130);
}

TEST(CliConventions, HugeFrameCountIsRefusedUpFront) {
  const auto r = run_bimart("graph " + std::string(BIMART_SOURCE_DIR) +
                            "/pipelines/smoke.yaml --set trajectory.frames=9000000000000");
  const auto run = run_bimart("run " + std::string(BIMART_SOURCE_DIR) +
                              "/pipelines/smoke.yaml --set trajectory.frames=9000000000000");
  EXPECT_EQ(exit_code(run.status), 1) << run.output;  // libtorch's allocator message before
  EXPECT_NE(run.output.find("frames must be at least 1 and at most 1000000, got 9000000000000"), std::string::npos) << run.output;
  (void)r;
}

}  // namespace
}  // namespace bimart
