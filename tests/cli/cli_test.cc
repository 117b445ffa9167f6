// The `bimart` program as a user runs it.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string output;  // stdout and stderr
};

Result bimart(const std::string& args, const std::string& env = "") {
  const std::string cmd = env + " " + BIMART_CLI + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), pipe)) out += buf.data();
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("bimart_cli_" + std::to_string(::getpid())) / name;
  fs::create_directories(p.parent_path());
  return p;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const std::string kSmoke = std::string(BIMART_SOURCE_DIR) + "/pipelines/smoke.yaml";

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "output: " << (haystack)

}  // namespace

TEST(Cli, VersionReportsLibtorchAndBlas) {
  const Result r = bimart("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_HAS(r.output, "bimart 0.");
  EXPECT_HAS(r.output, "libtorch");
  EXPECT_HAS(r.output, "BLAS");
}

TEST(Cli, PluginsListsBuiltInStagesFromTheirLibraries) {
  const Result r = bimart("plugins");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_HAS(r.output, "trajectory.constant  (kind trajectory)");
  EXPECT_HAS(r.output, "export.states_csv  (kind export)");
  EXPECT_HAS(r.output, "libbimart_smoke.so");
  EXPECT_HAS(r.output, "param  frames");
  const Result j = bimart("plugins --kind export --json");
  EXPECT_EQ(j.code, 0);
  EXPECT_HAS(j.output, "\"key\": \"export.states_csv\"");
  EXPECT_EQ(j.output.find("trajectory.constant"), std::string::npos);
}

TEST(Cli, RunSmokeWritesTheStates) {
  const fs::path out = scratch("smoke/states.csv");
  fs::remove(out);
  const Result r = bimart("run " + kSmoke + " --set write.path=" + out.string() + " --set trajectory.frames=5");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_HAS(r.output, "wrote " + out.string());
  const std::string csv = read(out);
  EXPECT_HAS(csv, "frame,time,angle,rx,ry,rz,tx,ty,tz\n");
  EXPECT_HAS(csv, "\n4,0.133333333,0.300000012,0,0,0,0,0,0.100000001\n");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 6);
}

TEST(Cli, SameSeedSameOutputOtherSeedOther) {
  const fs::path a = scratch("seed_a.csv"), b = scratch("seed_b.csv"), c = scratch("seed_c.csv");
  const std::string common = "run " + kSmoke + " --set trajectory.noise=0.01 --set write.path=";
  ASSERT_EQ(bimart(common + a.string() + " --seed 5").code, 0);
  ASSERT_EQ(bimart(common + b.string() + " --seed 5").code, 0);
  ASSERT_EQ(bimart(common + c.string() + " --seed 6").code, 0);
  EXPECT_EQ(read(a), read(b));
  EXPECT_NE(read(a), read(c));
}

TEST(Cli, ValidationErrorsNameTheFileLineAndColumn) {
  const fs::path bad = scratch("bad.yaml");
  std::ofstream(bad) << "stages:\n  - id: trajectory\n    use: trajectory.constnt\n";
  const Result r = bimart("run " + bad.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_HAS(r.output, bad.string() + ":3:10:");
  EXPECT_HAS(r.output, "did you mean 'trajectory.constant'");
  const Result o = bimart("graph " + kSmoke + " --set trajectory.frmes=3");
  EXPECT_EQ(o.code, 1);
  EXPECT_HAS(o.output, "--set trajectory.frmes=3: stage 'trajectory' (trajectory.constant) has no parameter 'frmes'");
}

TEST(Cli, BadParameterValueFailsBeforeWritingAnything) {
  const fs::path out = scratch("never.csv");
  fs::remove(out);
  const Result r = bimart("run " + kSmoke + " --set trajectory.frames=0 --set write.path=" + out.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_HAS(r.output, "frames must be at least 1");
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, GraphPrintsTheValidatedGraph) {
  const Result r = bimart("graph " + kSmoke);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_HAS(r.output, "1. trajectory  [trajectory.constant]");
  EXPECT_HAS(r.output, "in     fps <- trajectory.fps  (by name)");
  EXPECT_HAS(r.output, "in     object_states <- trajectory.object_states\n");
  EXPECT_HAS(bimart("graph --mermaid " + kSmoke).output, "trajectory -- object_states --> write");
}

TEST(Cli, ExtraLibrariesFromTheEnvironmentAndTheCommandLine) {
  const std::string lib = std::string(BIMART_TEST_PLUGIN_DIR) + "/libbimart_test_random.so";
  EXPECT_HAS(bimart("plugins", "BIMART_PLUGIN_PATH=" + lib).output, "export.random_numbers");
  EXPECT_HAS(bimart("--plugin " + lib + " plugins").output, "export.random_numbers");
  EXPECT_EQ(bimart("plugins").output.find("export.random_numbers"), std::string::npos);
}

TEST(Cli, BrokenLibraryInThePipelineIsReportedAtItsLine) {
  const fs::path p = scratch("with_lib.yaml");
  std::ofstream(p) << "plugins:\n  - " << BIMART_TEST_PLUGIN_DIR << "/libbimart_test_bad_abi.so\n"
                   << "stages:\n  - {id: t, use: trajectory.constant}\n";
  const Result r = bimart("run " + p.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_HAS(r.output, p.string() + ":2:5:");
  EXPECT_HAS(r.output, "plug-in ABI version 999");
}

TEST(Cli, HelpForEachCommand) {
  for (const char* cmd : {"run", "graph", "plugins", "info", "bench blas"}) {
    const Result r = bimart(std::string(cmd) + " --help");
    EXPECT_EQ(r.code, 0) << cmd;
    EXPECT_HAS(r.output, "Usage");
  }
}

TEST(Cli, ModelCheckNamesAMissingCheckpointOrDataSet) {
  EXPECT_EQ(bimart("model check --help").code, 0);
  const Result none = bimart("model check /nonexistent/m.npz /nonexistent/data");
  EXPECT_EQ(none.code, 1);
  EXPECT_HAS(none.output, "/nonexistent/m.npz");
  const Result data = bimart("model check " + std::string(BIMART_SOURCE_DIR) + "/models/contact.npz /nonexistent/data");
  EXPECT_EQ(data.code, 1);
  EXPECT_HAS(data.output, "/nonexistent/data");
}

TEST(Cli, EncodersRunInAPipelineWithTheirShippedBases) {
  const fs::path yaml = scratch("encoders.yaml");
  const fs::path out = scratch("encoders/states.csv");
  std::ofstream(yaml) << "name: encoders\nstages:\n"
                         "  - {id: trajectory, use: trajectory.constant, params: {frames: 4, angle: 0.5}}\n"
                         "  - {id: np, use: encoder.np_bps}\n"
                         "  - {id: npa, use: encoder.npa_bps}\n"
                         "  - {id: u, use: encoder.u_bps}\n"
                         "  - {id: write, use: export.states_csv, params: {path: " + out.string() + "}}\n";
  const Result r = bimart("run " + yaml.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_HAS(r.output, "np (encoder.np_bps)");
  EXPECT_HAS(r.output, "u (encoder.u_bps)");
  const Result bad = bimart("run " + yaml.string() + " --set np.basis=models/bps/npa_bps_1024.npz");
  EXPECT_NE(bad.code, 0);
  EXPECT_HAS(bad.output, "this encoder needs 512");
}
