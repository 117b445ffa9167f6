// Tests for core/runtime/blas: the kernel choice against the CPU's flags, the re-exec
// decision, thread settings, the BLAS report and the matmul benchmark's arithmetic.
// Tests that need a fresh process (OpenBLAS reads OPENBLAS_CORETYPE only when loaded) run
// this same binary again with a filter; their bodies are the DISABLED_ tests at the end.
#include "core/runtime/blas.h"

#include <gtest/gtest.h>

#include <dlfcn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/util/error.h"

extern char** environ;

namespace bimart::runtime {
namespace {

constexpr const char* kChildEnv = "BIMART_BLAS_TEST_CHILD";

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool openblas_loaded() { return dlsym(RTLD_DEFAULT, "openblas_get_corename") != nullptr; }

// ---- the CPU as /proc/cpuinfo describes it, read without the code under test ----

struct ProcCpu {
  bool found = false;
  std::string vendor;           // "GenuineIntel", "AuthenticAMD", ...
  std::set<std::string> flags;  // of the first processor
};

ProcCpu read_proc_cpuinfo() {
  ProcCpu cpu;
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon);
    key.erase(key.find_last_not_of(" \t") + 1);
    const std::string value = line.substr(colon + 1);
    if (key == "vendor_id" && cpu.vendor.empty()) {
      std::istringstream(value) >> cpu.vendor;
    } else if (key == "flags" && !cpu.found) {
      std::istringstream words(value);
      for (std::string w; words >> w;) cpu.flags.insert(w);
      cpu.found = true;
    }
  }
  return cpu;
}

// The rule of choose_openblas_coretype(), restated over /proc/cpuinfo's flag names.
std::string expected_coretype(const ProcCpu& cpu) {
  const auto has = [&](const char* f) { return cpu.flags.count(f) > 0; };
  const bool avx2_fma = has("avx2") && has("fma");
  if (avx2_fma && has("avx512f") && has("avx512vl") && has("avx512bw") && has("avx512dq")) {
    return "SkylakeX";
  }
  if (avx2_fma) return cpu.vendor == "AuthenticAMD" ? "Zen" : "Haswell";
  if (has("avx")) return "Sandybridge";
  return "";
}

// ---- running this test binary again as a child process ----

struct ChildResult {
  int exit_code = -1;  // -1 when it did not exit normally
  int signal = 0;      // the signal that ended it, if any
  std::string output;  // stdout and stderr together
};

// Runs /proc/self/exe with one gtest filter; `env` sets (value) or removes (nullopt)
// variables of the current environment. The environment is built before fork, so the
// child only calls async-signal-safe functions.
ChildResult run_self(const std::string& filter,
                     const std::map<std::string, std::optional<std::string>>& env) {
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    const std::string name = entry.substr(0, entry.find('='));
    if (env.count(name) == 0) env_strings.push_back(entry);
  }
  for (const auto& [name, value] : env) {
    if (value) env_strings.push_back(name + "=" + *value);
  }
  std::vector<char*> envp;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);

  std::string name_arg = "blas_test";
  std::string filter_arg = "--gtest_filter=" + filter;
  std::string disabled_arg = "--gtest_also_run_disabled_tests";
  char* argv[] = {name_arg.data(), filter_arg.data(), disabled_arg.data(), nullptr};

  ChildResult result;
  if (std::getenv(kChildEnv) != nullptr) {  // a child never starts another: no runaway
    result.output = "refused to start a child from a child";
    return result;
  }
  int fds[2];
  if (pipe(fds) != 0) return result;
  const pid_t pid = fork();
  if (pid < 0) return result;
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    close(fds[0]);
    close(fds[1]);
    execve("/proc/self/exe", argv, envp.data());
    _exit(127);
  }
  close(fds[1]);
  char buf[4096];
  for (ssize_t got; (got = read(fds[0], buf, sizeof(buf))) > 0;) result.output.append(buf, got);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  return result;
}

// Sets or restores one variable of this process for the length of a test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value != nullptr) {
      setenv(name, value, 1);
    } else {
      unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      setenv(name_.c_str(), old_->c_str(), 1);
    } else {
      unsetenv(name_.c_str());
    }
  }

 private:
  std::string name_;
  std::optional<std::string> old_;
};

// ---- choose_openblas_coretype ----

TEST(ChooseCoretype, BuiltinCpuSupportsAgreesWithProcCpuinfo) {
#if defined(__x86_64__) || defined(__i386__)
  const ProcCpu cpu = read_proc_cpuinfo();
  if (!cpu.found) GTEST_SKIP() << "no flags line in /proc/cpuinfo";
  __builtin_cpu_init();
#define BIMART_EXPECT_FLAG(f) \
  EXPECT_EQ(__builtin_cpu_supports(f) != 0, cpu.flags.count(f) > 0) << "feature " << f
  BIMART_EXPECT_FLAG("avx");
  BIMART_EXPECT_FLAG("avx2");
  BIMART_EXPECT_FLAG("fma");
  BIMART_EXPECT_FLAG("avx512f");
  BIMART_EXPECT_FLAG("avx512vl");
  BIMART_EXPECT_FLAG("avx512bw");
  BIMART_EXPECT_FLAG("avx512dq");
#undef BIMART_EXPECT_FLAG
  EXPECT_EQ(__builtin_cpu_is("amd") != 0, cpu.vendor == "AuthenticAMD");
#else
  GTEST_SKIP() << "not x86";
#endif
}

TEST(ChooseCoretype, MatchesProcCpuinfoFlags) {
#if defined(__x86_64__) || defined(__i386__)
  const ProcCpu cpu = read_proc_cpuinfo();
  if (!cpu.found) GTEST_SKIP() << "no flags line in /proc/cpuinfo";
  EXPECT_EQ(choose_openblas_coretype(), expected_coretype(cpu));
#else
  EXPECT_EQ(choose_openblas_coretype(), "");
#endif
}

// The chosen kernel must run here: a wrong choice (say SkylakeX without AVX-512) dies of
// SIGILL in the child instead of computing.
TEST(ChooseCoretype, ChosenKernelRunsAndComputes) {
  const std::string chosen = choose_openblas_coretype();
  if (chosen.empty() || !openblas_loaded()) GTEST_SKIP() << "nothing chosen or no OpenBLAS";
  const ChildResult r = run_self("*DISABLED_ChildKernelComputes",
                                 {{kChildEnv, "1"}, {kCoretypeEnv, chosen}});
  EXPECT_EQ(r.signal, 0) << "child killed by signal " << r.signal << "\n" << r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("[  PASSED  ] 1 test"), std::string::npos) << r.output;
}

// ---- reexec_coretype ----

class FakeEnv {
 public:
  FakeEnv& set(const std::string& name, const std::string& value) {
    vars_[name] = value;
    return *this;
  }
  std::function<const char*(const char*)> fn() const {
    return [this](const char* name) -> const char* {
      const auto it = vars_.find(name);
      return it == vars_.end() ? nullptr : it->second.c_str();
    };
  }

 private:
  std::map<std::string, std::string> vars_;
};

TEST(ReexecCoretype, ReexecsWithTheChoiceWhenNothingIsSet) {
  FakeEnv env;
  EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX"), "SkylakeX");
  EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX", "Prescott"), "SkylakeX");
}

TEST(ReexecCoretype, KeepsTheUsersOwnValue) {
  FakeEnv env;
  env.set(kCoretypeEnv, "Haswell");
  EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX", "Haswell"), "");
  env.set(kCoretypeEnv, "");  // an empty value is no choice
  EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX", "Prescott"), "SkylakeX");
}

TEST(ReexecCoretype, OptOut) {
  for (const char* off : {"0", "false", "OFF", "no"}) {
    FakeEnv env;
    env.set(kReexecEnv, off);
    EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX", "Prescott"), "") << off;
  }
  FakeEnv on;
  on.set(kReexecEnv, "1");
  EXPECT_EQ(reexec_coretype(on.fn(), true, "SkylakeX", "Prescott"), "SkylakeX");
}

TEST(ReexecCoretype, GuardStopsASecondReexec) {
  FakeEnv env;
  env.set(kReexecGuardEnv, "SkylakeX");
  EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX", "Prescott"), "");
}

TEST(ReexecCoretype, NothingWithoutOpenBlas) {
  FakeEnv env;
  EXPECT_EQ(reexec_coretype(env.fn(), false, "SkylakeX"), "");
}

TEST(ReexecCoretype, NothingWhenNothingWasChosen) {
  FakeEnv env;
  EXPECT_EQ(reexec_coretype(env.fn(), true, "", "Prescott"), "");
}

TEST(ReexecCoretype, NothingWhenOpenBlasAlreadyRunsTheChoice) {
  FakeEnv env;
  EXPECT_EQ(reexec_coretype(env.fn(), true, "Zen", "Zen"), "");
  EXPECT_EQ(reexec_coretype(env.fn(), true, "SkylakeX", "skylakex"), "");
  EXPECT_EQ(reexec_coretype(env.fn(), true, "Zen", "Haswell"), "Zen");
}

// ---- ensure_blas_kernel, end to end ----

// A child starts with OpenBLAS on the generic "Prescott" kernel (what OpenBLAS misdetects
// on some VMs), forgets the variable, and calls ensure_blas_kernel: it must restart itself
// once, with the chosen kernel, and the restarted process must not restart again.
TEST(EnsureBlasKernel, RestartsOnceOnAMisdetectedKernel) {
  const std::string chosen = choose_openblas_coretype();
  if (chosen.empty() || !openblas_loaded()) GTEST_SKIP() << "nothing chosen or no OpenBLAS";
  const ChildResult r =
      run_self("*DISABLED_ChildFromMisdetected",
               {{kChildEnv, "1"}, {kCoretypeEnv, "Prescott"}, {kReexecGuardEnv, std::nullopt},
                {kReexecEnv, std::nullopt}});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // The process that reports is the restarted one: it ran the second child test.
  EXPECT_NE(r.output.find("DISABLED_ChildAfterRestart"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[  PASSED  ] 1 test"), std::string::npos) << r.output;
}

TEST(EnsureBlasKernel, OptOutKeepsTheProcess) {
  const std::string chosen = choose_openblas_coretype();
  if (chosen.empty() || !openblas_loaded()) GTEST_SKIP() << "nothing chosen or no OpenBLAS";
  const ChildResult r =
      run_self("*DISABLED_ChildOptedOut", {{kChildEnv, "1"}, {kCoretypeEnv, "Prescott"},
                                           {kReexecGuardEnv, std::nullopt}, {kReexecEnv, "0"}});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("[  PASSED  ] 1 test"), std::string::npos) << r.output;
}

// ---- threads ----

TEST(SetThreads, SetsTorchAndOpenBlas) {
  set_threads(1);
  BlasInfo info = blas_info();
  EXPECT_EQ(info.torch_threads, 1);
  if (openblas_loaded()) {
    EXPECT_EQ(info.blas_threads, 1);
  }

  set_threads(2);
  info = blas_info();
  EXPECT_EQ(info.torch_threads, 2);
  if (openblas_loaded()) {
    EXPECT_EQ(info.blas_threads, 2);
  }

  set_threads(0);  // all cores
  const int all = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  info = blas_info();
  EXPECT_EQ(info.torch_threads, all);
  if (openblas_loaded()) {
    EXPECT_EQ(info.blas_threads, std::min(all, 64));  // OpenBLAS's cap
  }
}

// ---- blas_info / describe ----

TEST(BlasInfo, ReportsTheLoadedLibrary) {
  const BlasInfo info = blas_info();
  ASSERT_FALSE(info.library.empty());
  EXPECT_EQ(info.chosen_core, choose_openblas_coretype());
  EXPECT_GE(info.torch_threads, 1);
  EXPECT_GE(info.torch_interop_threads, 1);
  if (openblas_loaded()) {
    EXPECT_NE(lower(info.library).find("openblas"), std::string::npos) << info.library;
    EXPECT_EQ(info.config.rfind("OpenBLAS", 0), 0u) << info.config;
    EXPECT_FALSE(info.core.empty());
    EXPECT_GE(info.blas_threads, 1);
    EXPECT_FALSE(info.sgemm_library.empty());  // libtorch needs an sgemm_
  } else {
    EXPECT_EQ(info.library, "unknown (not OpenBLAS)");
    EXPECT_EQ(info.blas_threads, 0);
  }
}

TEST(BlasInfo, TellsWhoSetTheCoretype) {
  // Changing the variables after OpenBLAS has loaded changes nothing but the report.
  {
    ScopedEnv a(kCoretypeEnv, nullptr), b(kReexecGuardEnv, nullptr);
    EXPECT_EQ(blas_info().coretype_source, "not set");
  }
  {
    ScopedEnv a(kCoretypeEnv, "Haswell"), b(kReexecGuardEnv, nullptr);
    EXPECT_EQ(blas_info().coretype_source, "set by user");
  }
  {
    ScopedEnv a(kCoretypeEnv, "Haswell"), b(kReexecGuardEnv, "Haswell");
    EXPECT_EQ(blas_info().coretype_source, "chosen by bimart");
  }
  {
    ScopedEnv a(kCoretypeEnv, "Sandybridge"), b(kReexecGuardEnv, "Haswell");
    EXPECT_EQ(blas_info().coretype_source, "set by user");  // changed after bimart chose
  }
}

TEST(Describe, NamesLibraryKernelAndThreads) {
  set_threads(2);
  const BlasInfo info = blas_info();
  const std::string text = describe(info);
  EXPECT_NE(text.find("BLAS:"), std::string::npos) << text;
  EXPECT_NE(text.find("threads: 2 intra-op"), std::string::npos) << text;
  if (!info.core.empty()) {
    EXPECT_NE(text.find(info.core), std::string::npos) << text;
  }
  EXPECT_EQ(text.back(), '\n');
}

// DESIGN §8, issue 17: libtorch's products must reach OpenBLAS, whatever else is linked
// (Debian's Ceres brings ATLAS's libf77blas). Checked with dladdr, without blas_info().
std::string file_of(const char* symbol) {
  Dl_info where{};
  void* p = dlsym(RTLD_DEFAULT, symbol);
  if (p == nullptr || dladdr(p, &where) == 0 || where.dli_fname == nullptr) return "";
  char resolved[PATH_MAX];
  return realpath(where.dli_fname, resolved) != nullptr ? resolved : where.dli_fname;
}

TEST(BlasInfo, SgemmResolvesToOpenBlas) {
  const std::string sgemm = file_of("sgemm_");
  const std::string openblas = file_of("openblas_get_config");
  ASSERT_FALSE(openblas.empty()) << "OpenBLAS is not loaded in this process";
  ASSERT_FALSE(sgemm.empty()) << "no sgemm_ in this process";
  EXPECT_NE(lower(sgemm).find("openblas"), std::string::npos)
      << "sgemm_ resolves to " << sgemm << ", not to OpenBLAS (" << openblas << ")";
  const BlasInfo info = blas_info();
  EXPECT_EQ(info.sgemm_library, sgemm);
  EXPECT_TRUE(info.sgemm_in_openblas);
  EXPECT_EQ(describe(info).find("warning:"), std::string::npos) << describe(info);
}

TEST(SameOpenblas, SameFileOrItsWrapper) {
  const std::string dir = "/usr/lib/x86_64-linux-gnu/openblas-openmp/";
  EXPECT_TRUE(same_openblas(dir + "libopenblasp-r0.3.21.so", dir + "libopenblasp-r0.3.21.so"));
  EXPECT_TRUE(same_openblas(dir + "libblas.so.3", dir + "libopenblasp-r0.3.21.so"));
  EXPECT_FALSE(same_openblas("/usr/lib/x86_64-linux-gnu/libf77blas.so.3", dir + "libopenblasp-r0.3.21.so"));
  EXPECT_FALSE(same_openblas("", dir + "libopenblasp-r0.3.21.so"));
  EXPECT_FALSE(same_openblas("/usr/lib/libblas.so.3", "/usr/lib/libother.so"));  // folder not OpenBLAS's
}

TEST(Describe, WarnsWhenSgemmIsNotTheReportedOpenBlas) {
  BlasInfo info;
  info.library = "/usr/lib/x86_64-linux-gnu/openblas-openmp/libopenblasp-r0.3.21.so";
  info.config = "OpenBLAS 0.3.21 USE_OPENMP";
  info.core = "SkylakeX";
  info.sgemm_library = "/usr/lib/x86_64-linux-gnu/libf77blas.so.3";
  info.sgemm_in_openblas = false;
  const std::string text = describe(info);
  const auto warning = text.find("warning:");
  ASSERT_NE(warning, std::string::npos) << text;
  const std::string line = text.substr(warning, text.find('\n', warning) - warning);
  EXPECT_NE(line.find(info.sgemm_library), std::string::npos) << line;
  EXPECT_NE(line.find(info.library), std::string::npos) << line;
  info.sgemm_library = info.library;
  info.sgemm_in_openblas = true;
  EXPECT_EQ(describe(info).find("warning:"), std::string::npos);
}

// ---- bench_matmul ----

TEST(BenchMatmul, NumbersAreConsistent) {
  const MatmulBench b = bench_matmul(64, 3);
  EXPECT_EQ(b.n, 64);
  EXPECT_EQ(b.repeats, 3);
  EXPECT_TRUE(std::isfinite(b.seconds_median));
  EXPECT_TRUE(std::isfinite(b.seconds_max));
  EXPECT_TRUE(std::isfinite(b.gflops_median));
  EXPECT_GT(b.seconds_median, 0.0);
  EXPECT_GE(b.seconds_max, b.seconds_median);
  EXPECT_GT(b.gflops_median, 0.0);
  const double expected = 2.0 * 64 * 64 * 64 / b.seconds_median / 1e9;
  EXPECT_NEAR(b.gflops_median, expected, 1e-9 * expected);
}

TEST(BenchMatmul, DirectOpenBlasComputesTheSameProductRate) {
  if (!openblas_loaded()) GTEST_SKIP() << "OpenBLAS is not loaded";
  const MatmulBench d = bench_openblas_direct(64, 3);
  EXPECT_EQ(d.n, 64);
  EXPECT_GT(d.gflops_median, 0.0);
  EXPECT_THROW(bench_openblas_direct(0, 3), Error);
}

TEST(BenchMatmul, RejectsNonPositiveArguments) {
  EXPECT_THROW(bench_matmul(0, 3), Error);
  EXPECT_THROW(bench_matmul(-5, 3), Error);
  EXPECT_THROW(bench_matmul(16, 0), Error);
}

// ---- bodies run only in a child started by the tests above ----

bool in_child() { return std::getenv(kChildEnv) != nullptr; }

// sgemm_ as every BLAS exports it (column-major).
using SgemmFn = void (*)(const char*, const char*, const int*, const int*, const int*,
                         const float*, const float*, const int*, const float*, const int*,
                         const float*, float*, const int*);

// argv for ensure_blas_kernel() where it must not restart: if it does, the new process
// runs only a test that fails.
struct UnexpectedRestartArgv {
  std::string self = "blas_test";
  std::string filter = "--gtest_filter=*DISABLED_ChildUnexpectedRestart";
  std::string disabled = "--gtest_also_run_disabled_tests";
  char* argv[4] = {self.data(), filter.data(), disabled.data(), nullptr};
};

TEST(BlasChild, DISABLED_ChildKernelComputes) {
  if (!in_child()) GTEST_SKIP() << "runs as a child of ChosenKernelRunsAndComputes";
  const BlasInfo info = blas_info();
  EXPECT_EQ(lower(info.core), lower(choose_openblas_coretype()));
  const auto sgemm = reinterpret_cast<SgemmFn>(dlsym(RTLD_DEFAULT, "sgemm_"));
  ASSERT_NE(sgemm, nullptr);
  const int n = 97;  // odd, so the kernel's edge code runs too
  std::vector<float> a(n * n), b(n * n), c(n * n, 0.0f);
  for (int i = 0; i < n * n; ++i) {
    a[i] = static_cast<float>((i * 7) % 13) - 6.0f;
    b[i] = static_cast<float>((i * 5) % 11) - 5.0f;
  }
  const float one = 1.0f, zero = 0.0f;
  sgemm("N", "N", &n, &n, &n, &one, a.data(), &n, b.data(), &n, &zero, c.data(), &n);
  for (int col = 0; col < n; ++col) {
    for (int row = 0; row < n; ++row) {
      double want = 0;  // small integers: exact in float
      for (int k = 0; k < n; ++k) want += double(a[k * n + row]) * b[col * n + k];
      ASSERT_EQ(c[col * n + row], static_cast<float>(want)) << row << "," << col;
    }
  }
  (void)bench_matmul(128, 2);  // and through libtorch
}

TEST(BlasChild, DISABLED_ChildFromMisdetected) {
  if (!in_child()) GTEST_SKIP() << "runs as a child of RestartsOnceOnAMisdetectedKernel";
  ASSERT_EQ(blas_info().core, "Prescott");
  unsetenv(kCoretypeEnv);  // as if OpenBLAS had picked Prescott on its own
  std::string self = "blas_test", filter = "--gtest_filter=*DISABLED_ChildAfterRestart",
              disabled = "--gtest_also_run_disabled_tests";
  char* argv[] = {self.data(), filter.data(), disabled.data(), nullptr};
  ensure_blas_kernel(3, argv);
  FAIL() << "ensure_blas_kernel returned instead of restarting";
}

TEST(BlasChild, DISABLED_ChildAfterRestart) {
  if (!in_child()) GTEST_SKIP() << "runs as a child of RestartsOnceOnAMisdetectedKernel";
  const std::string chosen = choose_openblas_coretype();
  const BlasInfo info = blas_info();
  EXPECT_EQ(lower(info.core), lower(chosen));
  EXPECT_EQ(info.coretype_source, "chosen by bimart");
  ASSERT_NE(std::getenv(kReexecGuardEnv), nullptr);
  EXPECT_EQ(std::string(std::getenv(kReexecGuardEnv)), chosen);
  UnexpectedRestartArgv args;
  ensure_blas_kernel(3, args.argv);  // the guard is set: must return, not loop
}

TEST(BlasChild, DISABLED_ChildOptedOut) {
  if (!in_child()) GTEST_SKIP() << "runs as a child of OptOutKeepsTheProcess";
  unsetenv(kCoretypeEnv);
  UnexpectedRestartArgv args;
  ensure_blas_kernel(3, args.argv);  // BIMART_BLAS_REEXEC=0: returns
  EXPECT_EQ(blas_info().core, "Prescott");
  EXPECT_EQ(std::getenv(kReexecGuardEnv), nullptr);
}

TEST(BlasChild, DISABLED_ChildUnexpectedRestart) {
  if (!in_child()) GTEST_SKIP() << "runs only after a restart that should not have happened";
  FAIL() << "ensure_blas_kernel restarted the process where it should have returned";
}

}  // namespace
}  // namespace bimart::runtime
