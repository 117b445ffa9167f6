#include "core/pipeline/plugin_loader.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "core/pipeline/plugin.h"
#include "core/util/error.h"
#include "core/util/log.h"

namespace fs = std::filesystem;

namespace bimart {

namespace {

std::string str_or(const char* s) { return s ? s : "(null)"; }

void check_info(const std::string& path, const BimartPluginInfo* info) {
  auto refuse = [&](const std::string& what, const std::string& theirs, const std::string& ours) {
    throw Error("plug-in library " + path + " was built with " + what + " " + theirs +
                ", but this bimart uses " + ours + "; rebuild the plug-in against this installation");
  };
  if (info == nullptr) throw Error("plug-in library " + path + ": bimart_plugin_info() returned null");
  // Size and alignment first: nothing else in the struct can be trusted before them.
  if (info->struct_size != sizeof(BimartPluginInfo) || info->struct_align != alignof(BimartPluginInfo))
    refuse("a plug-in info struct of size/alignment",
           std::to_string(info->struct_size) + "/" + std::to_string(info->struct_align),
           std::to_string(sizeof(BimartPluginInfo)) + "/" + std::to_string(alignof(BimartPluginInfo)));
  if (info->abi_version != BIMART_PLUGIN_ABI_VERSION)
    refuse("plug-in ABI version", std::to_string(info->abi_version),
           std::to_string(BIMART_PLUGIN_ABI_VERSION));
  if (std::strcmp(str_or(info->compiler).c_str(), BIMART_COMPILER_ID) != 0)
    refuse("compiler", "'" + str_or(info->compiler) + "'", "'" BIMART_COMPILER_ID "'");
  if (info->cxx11_abi != BIMART_CXX11_ABI)
    refuse("_GLIBCXX_USE_CXX11_ABI =", std::to_string(info->cxx11_abi),
           std::to_string(BIMART_CXX11_ABI));
  if (std::strcmp(str_or(info->torch_version).c_str(), BIMART_TORCH_VERSION) != 0)
    refuse("libtorch", str_or(info->torch_version), BIMART_TORCH_VERSION);
}

}  // namespace

PluginLoader& PluginLoader::global() {
  static PluginLoader loader(Registry::global());
  return loader;
}

void PluginLoader::load(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error("plug-in library " + path + " does not exist");
  const std::string canonical = fs::canonical(path).string();
  for (const auto& lib : libraries_)
    if (lib.path == canonical) return;

  dlerror();
  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr)
    throw Error("cannot load plug-in library " + canonical + ": " + str_or(dlerror()));

  auto info_fn = reinterpret_cast<BimartPluginInfoFn>(dlsym(handle, BIMART_PLUGIN_INFO_SYMBOL));
  auto register_fn =
      reinterpret_cast<BimartPluginRegisterFn>(dlsym(handle, BIMART_PLUGIN_REGISTER_SYMBOL));
  if (info_fn == nullptr || register_fn == nullptr) {
    dlclose(handle);
    throw Error("plug-in library " + canonical + " is not a bimart plug-in: it does not export " +
                (info_fn == nullptr ? BIMART_PLUGIN_INFO_SYMBOL : BIMART_PLUGIN_REGISTER_SYMBOL) +
                " (build it with bimart_add_plugin)");
  }
  try {
    check_info(canonical, info_fn());
  } catch (...) {
    dlclose(handle);
    throw;
  }

  // From here the library's code has run; it stays loaded even if registration fails.
  PluginRegistrar registrar(canonical);
  try {
    register_fn(&registrar);
  } catch (const std::exception& e) {
    throw Error("plug-in library " + canonical + " failed while registering: " + e.what());
  }
  LoadedLibrary lib{canonical, {}};
  for (const auto& e : registrar.entries()) lib.stages.push_back(e.spec.key);
  registry_.add(std::move(registrar.entries()));
  log::debug("loaded {} ({} stages)", canonical, lib.stages.size());
  libraries_.push_back(std::move(lib));
}

void PluginLoader::load_directory(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  std::vector<std::string> files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".so" && fs::is_regular_file(it->path(), ec))
      files.push_back(it->path().string());
  if (ec) throw Error("cannot read plug-in folder " + dir + ": " + ec.message());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) load(f);
}

void PluginLoader::load_startup() {
  load_directory(builtin_plugin_dir());
  if (const char* env = std::getenv("BIMART_PLUGIN_PATH")) {
    std::stringstream ss(env);
    std::string item;
    while (std::getline(ss, item, ':')) {
      if (item.empty()) continue;
      std::error_code ec;
      if (fs::is_directory(item, ec))
        load_directory(item);
      else
        load(item);
    }
  }
}

std::string builtin_plugin_dir() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&builtin_plugin_dir), &info) == 0 || info.dli_fname == nullptr)
    return "";
  std::error_code ec;
  const fs::path lib = fs::weakly_canonical(info.dli_fname, ec);
  return ((ec ? fs::path(info.dli_fname) : lib).parent_path() / "bimart" / "plugins").string();
}

}  // namespace bimart
