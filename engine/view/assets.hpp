#pragma once
// The race view's page as files (docs/view.md): where they are installed, and a request's path
// mapped safely into that folder.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "engine/core/result.hpp"

namespace pitwall::view {

// Where the page's assets are: $PITWALL_VIEW_DIR, else web/ in each place pitwall's data may be
// (engine/core/data_dir.hpp: $PITWALL_DATA, the installed or the build tree's share/pitwall).
// The error names the places looked at.
Result<std::filesystem::path, std::string> findAssets();
// A request's path (its query dropped) mapped into the assets folder `root`; none for anything
// that could leave it: only letters, digits, '.', '_', '-' and '/', never "..", "//" or an
// absolute part. "/" is index.html.
std::optional<std::filesystem::path> assetPath(const std::filesystem::path& root,
                                               std::string_view target);
// The Content-Type of a file, by its extension.
std::string_view contentType(const std::filesystem::path& path);

}  // namespace pitwall::view
