#include "engine/cli/print_module.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "engine/core/data_dir.hpp"

namespace pitwall::cli {

namespace {

constexpr const char* kModule = "pitwall_print.so";

std::vector<std::filesystem::path> candidates() {
  std::vector<std::filesystem::path> out;
  if (const char* env = std::getenv("PITWALL_PRINT_MODULE"); env && *env) {
    std::error_code ec;  // dlopen reads a name without a slash as a library to search for
    const auto path = std::filesystem::absolute(env, ec);
    out.push_back(ec ? std::filesystem::path(env) : path);
    return out;
  }
  const std::filesystem::path exe = executableDir();
  if (!exe.empty()) {
    out.push_back(exe.parent_path() / "lib" / "pitwall" / kModule);  // installed: bin/../lib
    out.push_back(exe / "lib" / "pitwall" / kModule);                // the build tree
  }
  return out;
}

// The module's entry point `symbol`, or nothing with the reason on stderr. The module stays
// loaded for the rest of the process (it is one command's whole run).
void* entry(const char* command, const char* symbol) {
  std::string tried, why;
  for (const auto& path : candidates()) {
    tried += (tried.empty() ? "" : ", ") + path.string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* e = dlerror();
      why = e ? e : "unknown error";
      continue;
    }
    // The requests are C++ structs: the module must come from the same build as this binary.
    auto abi = reinterpret_cast<unsigned long (*)()>(dlsym(handle, "pitwall_print_abi"));
    if (!abi || abi() != print::kRequestAbi) {
      why = path.string() + " is from another build of pitwall (requests " +
            (abi ? std::to_string(abi()) : std::string("unknown")) + ", this one's " +
            std::to_string(print::kRequestAbi) + ")";
      continue;
    }
    if (void* fn = dlsym(handle, symbol)) return fn;
    why = path.string() + " has no " + symbol;
  }
  const bool fromEnv = std::getenv("PITWALL_PRINT_MODULE") && *std::getenv("PITWALL_PRINT_MODULE");
  std::cerr << "pitwall " << command << ": the print module cannot be loaded ("
            << (why.empty() ? "looked for " + tried : why) << "); "
            << (fromEnv ? "set $PITWALL_PRINT_MODULE to the pitwall_print.so of this build, or "
                          "unset it"
                        : "reinstall pitwall, or in a build tree build it: cmake --build build")
            << "\n";
  return nullptr;
}

template <class Request>
int run(const char* command, const char* symbol, const Request& request) {
  void* fn = entry(command, symbol);
  if (!fn) return 2;
  return reinterpret_cast<int (*)(const Request*)>(fn)(&request);
}

}  // namespace

int runPrintModule(const char* command, const print::PrintRequest& request) {
  return run(command, "pitwall_print_pieces", request);
}

int runPrintModule(const char* command, const print::VerifyRequest& request) {
  return run(command, "pitwall_verify_piece", request);
}

int runPrintModule(const char* command, const print::PngRequest& request) {
  return run(command, "pitwall_svg_png", request);
}

}  // namespace pitwall::cli
