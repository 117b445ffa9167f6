#include "core/runtime/blas.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/Parallel.h>
#include <c10/core/InferenceMode.h>

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

#include "core/util/error.h"

namespace bimart::runtime {
namespace {

// OpenBLAS's own entry points, looked up at run time so that any BLAS links and runs.
using GetStringFn = char* (*)();
using GetIntFn = int (*)();
using SetIntFn = void (*)(int);

template <typename Fn>
Fn find_symbol(const char* name) {
  return reinterpret_cast<Fn>(dlsym(RTLD_DEFAULT, name));
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The file a loaded symbol lives in, with symlinks (Debian's alternatives) resolved.
std::string library_of(void* symbol) {
  Dl_info where{};
  if (symbol == nullptr || dladdr(symbol, &where) == 0 || where.dli_fname == nullptr) return "";
  char resolved[PATH_MAX];
  if (realpath(where.dli_fname, resolved) != nullptr) return resolved;
  return where.dli_fname;
}

const char* env(const char* name) { return std::getenv(name); }

bool is_set(const char* value) { return value != nullptr && value[0] != '\0'; }

}  // namespace

std::string choose_openblas_coretype() {
#if defined(__x86_64__) || defined(__i386__)
  // __builtin_cpu_supports also checks that the OS saves the AVX / AVX-512 registers.
  __builtin_cpu_init();
  const bool avx = __builtin_cpu_supports("avx");
  const bool avx2_fma = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  if (avx512 && avx2_fma) return "SkylakeX";
  // OpenBLAS's Zen kernel is its Haswell code with AMD's cache sizes.
  if (avx2_fma) return __builtin_cpu_is("amd") ? "Zen" : "Haswell";
  if (avx) return "Sandybridge";
#endif
  return "";
}

std::string reexec_coretype(const std::function<const char*(const char*)>& getenv,
                            bool openblas_loaded, const std::string& chosen,
                            const std::string& loaded_core) {
  if (is_set(getenv(kCoretypeEnv))) return "";  // the user's own choice wins
  if (const char* opt = getenv(kReexecEnv); opt != nullptr) {
    const std::string v = lower(opt);
    if (v == "0" || v == "false" || v == "off" || v == "no") return "";
  }
  if (is_set(getenv(kReexecGuardEnv))) return "";  // this process is the re-executed one
  if (!openblas_loaded || chosen.empty()) return "";
  if (!loaded_core.empty() && lower(loaded_core) == lower(chosen)) return "";
  return chosen;
}

void ensure_blas_kernel(int argc, char** argv) {
  const auto corename = find_symbol<GetStringFn>("openblas_get_corename");
  const char* loaded = corename != nullptr ? corename() : nullptr;
  const std::string value = reexec_coretype(env, corename != nullptr, choose_openblas_coretype(),
                                            loaded != nullptr ? loaded : "");
  if (value.empty()) return;

  // /proc/self/exe is ld.so itself when the program was started as `ld.so ./bimart`;
  // re-executing that with our argv would not run bimart.
  char self[PATH_MAX];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (len <= 0) return;
  self[len] = '\0';
  if (std::strstr(self, "/ld-linux") != nullptr) return;

  std::vector<char*> args;
  for (int i = 0; argv != nullptr && i < argc; ++i) args.push_back(argv[i]);
  static char fallback_name[] = "bimart";
  if (args.empty()) args.push_back(fallback_name);
  args.push_back(nullptr);

  setenv(kCoretypeEnv, value.c_str(), 1);
  setenv(kReexecGuardEnv, value.c_str(), 1);
  // Restarting anyway: also stop OpenMP's spin-waiting, which halves 2-thread speed when the
  // other core is busy (docs/performance.md). A user's own setting is kept.
  const bool set_spin = std::getenv("GOMP_SPINCOUNT") == nullptr;
  if (set_spin) setenv("GOMP_SPINCOUNT", "0", 1);
  std::fflush(nullptr);  // anything already printed must not be lost or printed twice
  execv("/proc/self/exe", args.data());

  // Still here: exec failed. Undo, so children and blas_info() see the truth.
  const int err = errno;
  unsetenv(kCoretypeEnv);
  unsetenv(kReexecGuardEnv);
  if (set_spin) unsetenv("GOMP_SPINCOUNT");
  std::fprintf(stderr,
               "bimart: note: could not restart with %s=%s (%s); continuing with OpenBLAS's "
               "'%s' kernel\n",
               kCoretypeEnv, value.c_str(), std::strerror(err), loaded != nullptr ? loaded : "?");
}

BlasInfo blas_info() {
  BlasInfo info;
  const auto config = find_symbol<GetStringFn>("openblas_get_config");
  const auto corename = find_symbol<GetStringFn>("openblas_get_corename");
  const auto num_threads = find_symbol<GetIntFn>("openblas_get_num_threads");
  if (config != nullptr) {
    info.library = library_of(reinterpret_cast<void*>(config));
    if (info.library.empty()) info.library = "OpenBLAS (file unknown)";
    if (const char* c = config()) info.config = c;
  } else {
    info.library = "unknown (not OpenBLAS)";
  }
  if (corename != nullptr) {
    if (const char* c = corename()) info.core = c;
  }
  if (num_threads != nullptr) info.blas_threads = num_threads();
  info.sgemm_library = library_of(dlsym(RTLD_DEFAULT, "sgemm_"));
  info.sgemm_in_openblas = config != nullptr && same_openblas(info.sgemm_library, info.library);
  info.chosen_core = choose_openblas_coretype();

  info.torch_threads = at::get_num_threads();
  info.torch_interop_threads = at::get_num_interop_threads();

  const char* coretype = env(kCoretypeEnv);
  const char* guard = env(kReexecGuardEnv);
  if (!is_set(coretype)) {
    info.coretype_source = "not set";
  } else if (is_set(guard) && std::strcmp(guard, coretype) == 0) {
    info.coretype_source = "chosen by bimart";
  } else {
    info.coretype_source = "set by user";
  }
  return info;
}

bool same_openblas(const std::string& sgemm_file, const std::string& openblas_file) {
  if (sgemm_file.empty() || openblas_file.empty()) return false;
  if (sgemm_file == openblas_file) return true;
  const auto folder = [](const std::string& f) { return f.substr(0, f.find_last_of('/') + 1); };
  return folder(sgemm_file) == folder(openblas_file) &&
         folder(openblas_file).find("openblas") != std::string::npos;
}

std::string describe(const BlasInfo& info) {
  std::string s;
  if (!info.config.empty()) {
    s += "BLAS:    " + info.config + "\n";
    s += "         " + info.library + "\n";
  } else {
    s += "BLAS:    " + info.library + "\n";
  }
  s += "sgemm_:  " + (info.sgemm_library.empty() ? std::string("not found") : info.sgemm_library) +
       "\n";
  if (!info.config.empty() && !info.sgemm_in_openblas) {
    s += "warning: libtorch's matrix products call sgemm_ in " +
         (info.sgemm_library.empty() ? std::string("no library found") : info.sgemm_library) +
         ", not in the OpenBLAS reported here (" + info.library +
         "): they run slower, without its kernel and threads (docs/performance.md, BLAS)\n";
  }
  if (!info.core.empty()) {
    const char* value = env(kCoretypeEnv);
    std::string how = "OPENBLAS_CORETYPE " + info.coretype_source;
    if (is_set(value)) how += " (" + std::string(value) + ")";
    s += "kernel:  " + info.core + " (" + how + ")\n";
    if (!info.chosen_core.empty() && lower(info.core) != lower(info.chosen_core)) {
      s += "note:    this CPU can run OpenBLAS's '" + info.chosen_core +
           "' kernel; unset OPENBLAS_CORETYPE and BIMART_BLAS_REEXEC to let bimart pick it\n";
    }
  }
  s += "threads: " + std::to_string(info.torch_threads) + " intra-op, " +
       std::to_string(info.torch_interop_threads) + " inter-op";
  if (info.blas_threads > 0) s += ", " + std::to_string(info.blas_threads) + " BLAS";
  s += "\n";
  return s;
}

void set_threads(int n) {
  if (n <= 0) n = static_cast<int>(std::thread::hardware_concurrency());
  if (n <= 0) n = 1;  // hardware_concurrency() may not know
  at::set_num_threads(n);  // also omp_set_num_threads
  // OpenBLAS's OpenMP build follows OpenMP upward only once it left 1 thread: tell it too.
  if (const auto set = find_symbol<SetIntFn>("openblas_set_num_threads")) set(n);
}

namespace {

// One warm-up call of `product` (thread pool start, page faults, BLAS buffers), then
// `repeats` timed calls.
MatmulBench time_matmul(int n, int repeats, const std::function<void()>& product) {
  if (n <= 0) throw Error("matmul benchmark: size must be positive, got " + std::to_string(n));
  if (repeats <= 0) {
    throw Error("matmul benchmark: repeats must be positive, got " + std::to_string(repeats));
  }
  product();
  std::vector<double> seconds;
  seconds.reserve(static_cast<std::size_t>(repeats));
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    product();
    const auto t1 = std::chrono::steady_clock::now();
    seconds.push_back(std::chrono::duration<double>(t1 - t0).count());
  }
  std::sort(seconds.begin(), seconds.end());
  const std::size_t mid = seconds.size() / 2;
  const double median =
      seconds.size() % 2 == 1 ? seconds[mid] : 0.5 * (seconds[mid - 1] + seconds[mid]);

  MatmulBench r;
  r.n = n;
  r.repeats = repeats;
  r.seconds_median = median;
  r.seconds_max = seconds.back();
  const double flops = 2.0 * static_cast<double>(n) * n * n;
  r.gflops_median = median > 0 ? flops / median / 1e9 : 0.0;
  return r;
}

struct Operands {
  at::Tensor a, b, c;
};

Operands random_operands(int n) {
  if (n <= 0) throw Error("matmul benchmark: size must be positive, got " + std::to_string(n));
  auto gen = at::detail::createCPUGenerator(/*seed_val=*/12345);
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  return {at::randn({n, n}, gen, opts), at::randn({n, n}, gen, opts), at::empty({n, n}, opts)};
}

}  // namespace

MatmulBench bench_matmul(int n, int repeats) {
  c10::InferenceMode no_autograd;
  Operands m = random_operands(n);
  return time_matmul(n, repeats, [&] { at::mm_out(m.c, m.a, m.b); });
}

MatmulBench bench_openblas_direct(int n, int repeats) {
  // cblas_sgemm(order, transA, transB, M, N, K, alpha, A, lda, B, ldb, beta, C, ldc), taken
  // from the file that holds openblas_get_config, so it is OpenBLAS's whatever else is loaded.
  using CblasSgemm = void (*)(int, int, int, int, int, int, float, const float*, int, const float*,
                              int, float, float*, int);
  const std::string file = library_of(dlsym(RTLD_DEFAULT, "openblas_get_config"));
  if (file.empty()) throw Error("no OpenBLAS is loaded in this process: nothing to compare with");
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_NOLOAD);
  if (handle == nullptr) throw Error("cannot reopen the loaded OpenBLAS " + file);
  const auto sgemm = reinterpret_cast<CblasSgemm>(dlsym(handle, "cblas_sgemm"));
  dlclose(handle);  // RTLD_NOLOAD took a reference; the library stays loaded
  if (sgemm == nullptr) throw Error(file + " has no cblas_sgemm");
  Operands m = random_operands(n);
  constexpr int kRowMajor = 101, kNoTrans = 111;
  return time_matmul(n, repeats, [&] {
    sgemm(kRowMajor, kNoTrans, kNoTrans, n, n, n, 1.0f, m.a.data_ptr<float>(), n,
          m.b.data_ptr<float>(), n, 0.0f, m.c.data_ptr<float>(), n);
  });
}

}  // namespace bimart::runtime
