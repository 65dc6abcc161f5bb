#include "engine/view/assets.hpp"

#include <cctype>
#include <cstdlib>
#include <vector>

#include "engine/core/data_dir.hpp"

namespace pitwall::view {

Result<std::filesystem::path, std::string> findAssets() {
  std::vector<std::filesystem::path> places;
  if (const char* env = std::getenv("PITWALL_VIEW_DIR"); env && *env) places.emplace_back(env);
  for (const auto& data : dataDirCandidates()) places.push_back(data / "web");
  std::string looked;
  for (const auto& p : places) {
    std::error_code ec;
    if (std::filesystem::exists(p / "index.html", ec))
      return std::filesystem::weakly_canonical(p, ec);
    looked += (looked.empty() ? "" : ", ") + p.string();
  }
  return Unexpected{
      "the race view's page is not installed (looked in " + looked +
      "); build it (./dev build), install pitwall, or set PITWALL_VIEW_DIR to its folder"};
}

std::optional<std::filesystem::path> assetPath(const std::filesystem::path& root,
                                               std::string_view target) {
  if (auto q = target.find('?'); q != std::string_view::npos) target = target.substr(0, q);
  if (target.empty() || target[0] != '/') return std::nullopt;
  std::string rel(target.substr(1));
  if (rel.empty()) rel = "index.html";
  for (char c : rel)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' ||
          c == '/'))
      return std::nullopt;
  // never absolute (root / "/etc/passwd" is /etc/passwd), never up, never empty parts
  if (rel.front() == '/' || rel.find("..") != std::string::npos ||
      rel.find("//") != std::string::npos)
    return std::nullopt;
  return root / rel;
}

std::string_view contentType(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".ico") return "image/x-icon";
  return "application/octet-stream";
}

}  // namespace pitwall::view
