// The binary contract between the host and a plug-in library. A library exports two C
// functions; the host reads the info first and refuses the library, with a message, unless
// every field matches its own. Only then does it call the register function.
//
// The identity macros below are expanded where BIMART_REGISTER_STAGE is used, i.e. in the
// plug-in's own sources, so the info describes how the plug-in itself was compiled.
#pragma once

#include <cstdint>

#include <torch/version.h>

#include "core/version.h"

// 2: Guidance::placement (2026-12-03).
#define BIMART_PLUGIN_ABI_VERSION 2u

namespace bimart {
class PluginRegistrar;
}

extern "C" {

struct BimartPluginInfo {
  std::uint32_t struct_size;   // sizeof(BimartPluginInfo) in the library
  std::uint32_t struct_align;  // alignof(BimartPluginInfo)
  std::uint32_t abi_version;   // BIMART_PLUGIN_ABI_VERSION
  const char* bimart_version;  // BIMART_VERSION_STRING (informational; the ABI version decides)
  const char* compiler;        // compiler id and version
  const char* torch_version;   // libtorch version the library was built against
  std::int32_t cxx11_abi;      // _GLIBCXX_USE_CXX11_ABI
};

typedef const BimartPluginInfo* (*BimartPluginInfoFn)();
typedef void (*BimartPluginRegisterFn)(bimart::PluginRegistrar*);

}  // extern "C"

#define BIMART_PLUGIN_INFO_SYMBOL "bimart_plugin_info"
#define BIMART_PLUGIN_REGISTER_SYMBOL "bimart_plugin_register"

// Compile-time identity of this translation unit, compared field by field by the loader.
#define BIMART_TORCH_VERSION TORCH_VERSION
#ifndef BIMART_COMPILER_ID  // may be predefined only by tests
#if defined(__clang__)
#define BIMART_COMPILER_ID "clang " __clang_version__
#elif defined(__GNUC__)
#define BIMART_COMPILER_ID "gcc " __VERSION__
#else
#define BIMART_COMPILER_ID "unknown"
#endif
#endif
#ifdef _GLIBCXX_USE_CXX11_ABI
#define BIMART_CXX11_ABI _GLIBCXX_USE_CXX11_ABI
#else
#define BIMART_CXX11_ABI -1
#endif

// The info of the translation unit this macro is expanded in.
#define BIMART_THIS_BUILD_INFO                                                          \
  BimartPluginInfo {                                                                    \
    sizeof(BimartPluginInfo), alignof(BimartPluginInfo), BIMART_PLUGIN_ABI_VERSION,     \
        BIMART_VERSION_STRING, BIMART_COMPILER_ID, BIMART_TORCH_VERSION, BIMART_CXX11_ABI \
  }
