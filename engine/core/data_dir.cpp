#include "engine/core/data_dir.hpp"

#include <unistd.h>

#include <cstdlib>

namespace pitwall {

std::filesystem::path executableDir() {
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return exe.parent_path();
}

std::vector<std::filesystem::path> dataDirCandidates() {
  std::vector<std::filesystem::path> places;
  if (const char* env = std::getenv("PITWALL_DATA"); env && *env) places.emplace_back(env);
  if (auto exe = executableDir(); !exe.empty()) {
    places.push_back(exe.parent_path() / "share" / "pitwall");
    places.push_back(exe / "share" / "pitwall");
  }
  return places;
}

Result<std::filesystem::path, std::string> dataDir() {
  // $PITWALL_DATA overrides: a wrong one is an error, not a silent fall back to another tree.
  if (const char* env = std::getenv("PITWALL_DATA"); env && *env) {
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::path(env) / "scripts" / "pitwall" / "core.lua",
                                ec))
      return std::filesystem::weakly_canonical(env, ec);
    return Unexpected{std::string("PITWALL_DATA=") + env +
                      " holds no scripts/pitwall/core.lua; point it at a folder with pitwall's "
                      "data (an installed share/pitwall) or unset it"};
  }
  std::string looked;
  for (const auto& p : dataDirCandidates()) {
    std::error_code ec;
    if (std::filesystem::exists(p / "scripts" / "pitwall" / "core.lua", ec))
      return std::filesystem::weakly_canonical(p, ec);
    looked += (looked.empty() ? "" : ", ") + p.lexically_normal().string();
  }
  return Unexpected{
      "pitwall's data (scripts/pitwall/core.lua) is not where the binary expects it "
      "(looked in " +
      looked +
      "); install pitwall (cmake --install, or the .deb), run it from its build "
      "folder, or set PITWALL_DATA to the folder that holds scripts/"};
}

}  // namespace pitwall
