// The loader against real libraries: the built-in smoke library and libraries broken on
// purpose (see tests/plugins/CMakeLists.txt). A broken library is refused with a message
// naming it, and registers nothing.
#include <gtest/gtest.h>

#include <dlfcn.h>

#include "core/pipeline/plugin_loader.h"
#include "core/runtime/blas.h"

using namespace bimart;

namespace {

std::string test_lib(const std::string& name) {
  return std::string(BIMART_TEST_PLUGIN_DIR) + "/libbimart_" + name + ".so";
}
std::string smoke_lib() { return std::string(BIMART_BUILTIN_PLUGIN_DIR) + "/libbimart_smoke.so"; }

// Loads `lib` into a fresh registry (after `first`, if given) and returns the error text.
std::string refusal(const std::string& lib, Registry& r, const std::string& first = "") {
  PluginLoader loader(r);
  if (!first.empty()) loader.load(first);
  const std::size_t before = r.size();
  try {
    loader.load(lib);
  } catch (const Error& e) {
    EXPECT_EQ(r.size(), before) << "a refused library registered stages";
    return e.what();
  }
  ADD_FAILURE() << lib << " was loaded";
  return "";
}

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "message: " << (haystack)

}  // namespace

TEST(PluginLoader, LoadsTheBuiltInSmokeLibrary) {
  Registry r;
  PluginLoader loader(r);
  loader.load(smoke_lib());
  ASSERT_NE(r.find("trajectory.constant"), nullptr);
  ASSERT_NE(r.find("export.states_csv"), nullptr);
  EXPECT_HAS(r.get("trajectory.constant").library, "libbimart_smoke.so");
  ASSERT_EQ(loader.libraries().size(), 1u);
  EXPECT_EQ(loader.libraries()[0].stages.size(), 2u);
  // The spec came across intact: the kind's ports and the implementation's parameters.
  const StageSpec& s = r.get("trajectory.constant").spec;
  EXPECT_NE(s.find_output("object_states"), nullptr);
  EXPECT_EQ(s.find_param("frames")->type, ParamType::Int);
  // Loading the same library again is a no-op, not a duplicate.
  EXPECT_NO_THROW(loader.load(smoke_lib()));
  EXPECT_EQ(loader.libraries().size(), 1u);
}

TEST(PluginLoader, BuiltInDirectoryIsFoundNextToTheCoreLibrary) {
  EXPECT_EQ(builtin_plugin_dir(), BIMART_BUILTIN_PLUGIN_DIR);
}

TEST(PluginLoader, RefusesAbiVersionMismatch) {
  Registry r;
  EXPECT_HAS(refusal(test_lib("test_bad_abi"), r), "plug-in ABI version 999");
}

TEST(PluginLoader, RefusesInfoStructOfAnotherSize) {
  Registry r;
  EXPECT_HAS(refusal(test_lib("test_bad_size"), r), "size/alignment");
}

TEST(PluginLoader, RefusesAnotherCompiler) {
  Registry r;
  const std::string m = refusal(test_lib("test_bad_compiler"), r);
  EXPECT_HAS(m, "was built with compiler 'gcc 2.95'");
  EXPECT_HAS(m, "rebuild the plug-in");
}

TEST(PluginLoader, CompilerIdentityComesFromThePluginsOwnSources) {
  Registry r;
  EXPECT_HAS(refusal(test_lib("test_other_compiler"), r), "was built with compiler 'clang 99.0'");
  PluginLoader loader(r);
  EXPECT_NO_THROW(loader.load(test_lib("test_random")));  // same source, this compiler
}

TEST(PluginLoader, RefusesAnotherLibtorch) {
  Registry r;
  EXPECT_HAS(refusal(test_lib("test_bad_torch"), r), "libtorch 0.4.1");
}

TEST(PluginLoader, RefusesALibraryWithoutEntryPoints) {
  Registry r;
  EXPECT_HAS(refusal(test_lib("test_no_entry"), r), "is not a bimart plug-in");
}

TEST(PluginLoader, RefusesALibraryWithAnUnresolvedSymbol) {
  Registry r;
  const std::string m = refusal(test_lib("test_undefined"), r);
  EXPECT_HAS(m, "cannot load plug-in library");
  EXPECT_HAS(m, "bimart_test_function_that_does_not_exist");
}

TEST(PluginLoader, RefusesADuplicateRegistration) {
  Registry r;
  const std::string m = refusal(test_lib("test_duplicate"), r, smoke_lib());
  EXPECT_HAS(m, "duplicate stage 'trajectory.constant'");
  EXPECT_HAS(m, "libbimart_smoke.so");
  EXPECT_HAS(m, "libbimart_test_duplicate.so");
}

TEST(PluginLoader, RefusesTheSameKeyTwiceInOneLibrary) {
  Registry r;
  EXPECT_HAS(refusal(test_lib("test_twice"), r), "duplicate stage 'export.same_name': registered twice by");
}

TEST(PluginLoader, MissingFile) {
  Registry r;
  EXPECT_HAS(refusal("/nonexistent/libx.so", r), "/nonexistent/libx.so does not exist");
}

// DESIGN §8: a plug-in that links Ceres (ATLAS on Debian) must still reach OpenBLAS when it
// calls sgemm_, as libtorch inside it does: plug-ins share the host's load order.
TEST(PluginLoader, SgemmInsideAPluginIsOpenBlas) {
  Registry r;
  PluginLoader loader(r);
  const std::string lib = test_lib("test_blas_probe");
  loader.load(lib);
  void* handle = dlopen(lib.c_str(), RTLD_NOW | RTLD_NOLOAD);
  ASSERT_NE(handle, nullptr) << lib << " is not loaded";
  using Probe = const char* (*)();
  const auto probe = reinterpret_cast<Probe>(dlsym(handle, "bimart_test_sgemm_library"));
  ASSERT_NE(probe, nullptr);
  const std::string bound = probe();
  dlclose(handle);
  const runtime::BlasInfo info = runtime::blas_info();
  ASSERT_FALSE(info.config.empty()) << "OpenBLAS is not loaded in the test process";
  EXPECT_TRUE(runtime::same_openblas(bound, info.library))
      << "the plug-in's sgemm_ is bound to " << bound << ", not to OpenBLAS (" << info.library << ")";
}
