// The BLAS that libtorch calls: choosing OpenBLAS's kernel, thread counts, a report and a
// matmul benchmark (DESIGN §8). No torch header here; only blas.cc sees libtorch.
//
// Debian's OpenBLAS picks its kernel from cpuid once, when the library is loaded, and on
// some virtual machines it picks a slow generic one ("Prescott"). The only remedy that
// works with the system library is to set OPENBLAS_CORETYPE and start the program again,
// which ensure_blas_kernel() does once, at the top of main().
#pragma once

#include <functional>
#include <string>

namespace bimart::runtime {

// Environment variables this module reads or writes.
inline constexpr const char* kCoretypeEnv = "OPENBLAS_CORETYPE";  // read by OpenBLAS
inline constexpr const char* kReexecEnv = "BIMART_BLAS_REEXEC";   // "0" turns re-exec off
// Set by bimart to the core type it chose, so the new process does not re-exec again and
// blas_info() can tell bimart's choice from a user's.
inline constexpr const char* kReexecGuardEnv = "BIMART_BLAS_REEXECED";

// OpenBLAS's name for the best kernel this CPU (and OS) can run, judged by features:
// AVX-512 F/VL/BW/DQ -> "SkylakeX"; AVX2+FMA -> "Zen" on AMD, "Haswell" otherwise;
// AVX -> "Sandybridge"; anything older, or not x86 -> "" (leave it to OpenBLAS).
std::string choose_openblas_coretype();

// The decision inside ensure_blas_kernel(), kept pure for tests. Returns the core type to
// set before re-executing, or "" to run on as we are. "" when: the user set
// OPENBLAS_CORETYPE (a non-empty value is kept), BIMART_BLAS_REEXEC is an opt-out
// ("0", "false", "off", "no"), the guard is set (we already re-executed), OpenBLAS is not
// loaded, nothing was chosen, or the loaded OpenBLAS already runs `chosen` (`loaded_core`
// is openblas_get_corename(), compared without case; "" = unknown).
std::string reexec_coretype(const std::function<const char*(const char*)>& getenv,
                            bool openblas_loaded, const std::string& chosen,
                            const std::string& loaded_core = "");

// Call first thing in main(). When reexec_coretype() says so, sets OPENBLAS_CORETYPE and the
// guard and replaces the process with a fresh copy of itself (same argv, same environment
// otherwise), so OpenBLAS loads with the right kernel. If that fails it undoes the two
// variables, prints one note on stderr and returns; the program runs on, only slower.
void ensure_blas_kernel(int argc, char** argv);

struct BlasInfo {
  std::string library;          // file of the loaded OpenBLAS, or "unknown (not OpenBLAS)"
  std::string sgemm_library;    // file whose sgemm_ the process binds to ("" = none found)
  // sgemm_ lives in the OpenBLAS of `library` (the wrapper libblas.so.3 of the same
  // OpenBLAS folder counts): what libtorch's products run on.
  bool sgemm_in_openblas = false;
  std::string config;           // openblas_get_config(), e.g. "OpenBLAS 0.3.21 ... USE_OPENMP"
  std::string core;             // openblas_get_corename(): the kernel in use
  std::string chosen_core;      // choose_openblas_coretype() on this machine
  int blas_threads = 0;         // openblas_get_num_threads(); 0 = not OpenBLAS
  int torch_threads = 0;        // at::get_num_threads() (intra-op)
  int torch_interop_threads = 0;  // at::get_num_interop_threads()
  std::string coretype_source;  // "chosen by bimart", "set by user" or "not set"
};

// Reads the state of this process; never fails (fields it cannot learn are left empty/0).
BlasInfo blas_info();

// A few lines for `bimart info` / `bimart --version`, each ending in '\n'. When sgemm_
// does not resolve to the OpenBLAS whose kernel is reported, a "warning:" line names both.
std::string describe(const BlasInfo& info);

// True when `sgemm_file` is OpenBLAS: the same file as `openblas_file`, or a file in the
// same folder (Debian's libblas.so.3 wrapper of that OpenBLAS). Pure, for tests.
bool same_openblas(const std::string& sgemm_file, const std::string& openblas_file);

// Sets libtorch's intra-op threads (and so OpenMP's) and OpenBLAS's to n;
// n <= 0 means all cores (std::thread::hardware_concurrency()).
void set_threads(int n);

struct MatmulBench {
  int n = 0;
  int repeats = 0;
  double seconds_median = 0;  // per n x n matmul
  double seconds_max = 0;
  double gflops_median = 0;   // 2 n^3 / seconds_median / 1e9
};

// Times a float32 n x n matmul through libtorch: one warm-up, then `repeats` timed runs
// with the current thread settings. Throws bimart::Error if n or repeats is not positive.
MatmulBench bench_matmul(int n, int repeats);

// The same product through OpenBLAS's own cblas_sgemm (looked up in the loaded OpenBLAS,
// bypassing whatever sgemm_ libtorch binds to): the reference bench_matmul is compared
// with. Throws bimart::Error when no OpenBLAS is loaded.
MatmulBench bench_openblas_direct(int n, int repeats);

}  // namespace bimart::runtime
