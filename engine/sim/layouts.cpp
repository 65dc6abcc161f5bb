// Named layouts and layout files (docs/simulator.md "Layouts").
#include <array>
#include <filesystem>
#include <fstream>

#include "engine/core/suggest.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::sim {

namespace {

// A failed parse: one sentence saying what is wrong and what to do.
Unexpected<std::string> fail(std::string why) {
  return {std::move(why)};
}

struct Named {
  std::string_view name;
  std::string_view text;
};

// Each closes (checked by parseLayout, pinned by tests/unit/sim/track_test.cpp).
constexpr std::array<Named, 3> kLayouts{{
    // The default: a starter-kit oval, 1.12 m straights joined by half circles, ≈4.0 m.
    {"oval", "start S L L S S L L"},
    // A kidney: one right-hand bend dents the top of the loop; 5 left curves and 1 right.
    {"kidney", "start S L L S R L L S L"},
    // A longer oval with 1.68 m straights, for higher speeds between the curves.
    {"long", "start S S L L S S S L L"},
}};

std::string namesList() {
  std::string out;
  for (const Named& n : kLayouts) {
    if (!out.empty()) out += ", ";
    out += n.name;
  }
  return out;
}

}  // namespace

std::vector<std::string> layoutNames() {
  std::vector<std::string> out;
  for (const Named& n : kLayouts) out.emplace_back(n.name);
  return out;
}

Result<Track, std::string> namedLayout(std::string_view name) {
  for (const Named& n : kLayouts)
    if (n.name == name) return parseLayout(n.text, std::string(n.name));
  return fail("there is no layout named '" + std::string(name) + "'; named layouts are " +
              namesList());
}

Result<Track, std::string> loadLayout(std::string_view nameOrPath) {
  for (const Named& n : kLayouts)
    if (n.name == nameOrPath) return namedLayout(nameOrPath);

  std::filesystem::path path{std::string(nameOrPath)};
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail("layout '" + std::string(nameOrPath) + "' is neither a named layout (" +
                namesList() + ") nor a file that exists" + didYouMean(nameOrPath, layoutNames()) +
                " (give a name or the path of a layout file)");
  // The size first, then a read of at most one byte more than allowed (the file may grow).
  auto tooLarge = [&](std::uintmax_t bytes) {
    return fail(path.string() + " is " + std::to_string(bytes) + " bytes, more than the " +
                std::to_string(kMaxLayoutFileBytes) + " a layout file may be (" +
                std::to_string(kMaxPieces) +
                " pieces fit in a tenth of that); give the file of a layout, not another file");
  };
  if (const auto bytes = std::filesystem::file_size(path, ec); !ec && bytes > kMaxLayoutFileBytes)
    return tooLarge(bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot read layout file '" + path.string() + "'; check its permissions");
  std::string text(kMaxLayoutFileBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxLayoutFileBytes) return tooLarge(text.size());
  auto track = parseLayout(text, path.stem().string());
  if (!track) return fail(path.string() + ": " + track.error());
  return track;
}

}  // namespace pitwall::sim
