// Watching script files for hot reload: real files in a scratch folder, a real-clock loop.
#include "engine/core/file_watch.hpp"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/support/run_until.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {
struct Folder {
  fs::path dir;
  Folder() {
    char tmpl[] = "/tmp/pitwall-watch-XXXXXX";
    dir = ::mkdtemp(tmpl);
  }
  ~Folder() { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

struct Watching {
  Loop loop{ClockKind::Real};
  Folder folder;
  FileWatch watch{loop, 30ms};
  std::vector<std::vector<std::string>> reports;
  Watching() {
    watch.onChange = [this](const std::vector<std::string>& paths) { reports.push_back(paths); };
  }
  bool reported(std::size_t n) {
    return testing::runUntil(
        loop, [&] { return reports.size() >= n; }, 3s);
  }
};
}  // namespace

TEST_CASE_FIXTURE(Watching, "a file written in place is reported once, debounced") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  loop.post([&] {
    folder.write("race.lua", "print(2)");
    folder.write("race.lua", "print(3)");  // two saves in a row: one report
  });
  REQUIRE(reported(1));
  testing::runFor(loop, 100ms);
  REQUIRE(reports.size() == 1);
  CHECK(reports[0] == std::vector<std::string>{script});
}

TEST_CASE_FIXTURE(Watching, "an editor's atomic save (write a temporary file, rename it over)") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  loop.post([&] {
    auto tmp = folder.write(".race.lua.swp", "print(2)");
    fs::rename(tmp, script);
  });
  REQUIRE(reported(1));
  CHECK(reports[0] == std::vector<std::string>{script});
}

TEST_CASE_FIXTURE(Watching, "a backup-and-rewrite save: reported when the new file is there") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  loop.post([&] {
    fs::rename(script, folder.dir / "race.lua~");
    loop.after(60ms, [&] { folder.write("race.lua", "print(2)"); });  // after the debounce
  });
  REQUIRE(reported(1));
  CHECK(reports[0] == std::vector<std::string>{script});
  CHECK(fs::exists(script));
}

TEST_CASE_FIXTURE(Watching,
                  "other files in the folder are not reported; several watched files are") {
  auto a = folder.write("a.lua", "");
  auto b = folder.write("b.lua", "");
  REQUIRE(watch.add(a));
  REQUIRE(watch.add(b));
  CHECK(watch.files().size() == 2);
  loop.post([&] { folder.write("notes.txt", "unrelated"); });
  testing::runFor(loop, 100ms);
  CHECK(reports.empty());
  loop.post([&] {
    folder.write("a.lua", "1");
    folder.write("b.lua", "2");
  });
  REQUIRE(reported(1));
  CHECK(reports[0].size() == 2);
}

TEST_CASE("a file in a folder that does not exist is refused with the reason") {
  Loop loop{ClockKind::Real};
  FileWatch watch{loop};
  auto added = watch.add("/nonexistent-pitwall-folder/race.lua");
  REQUIRE_FALSE(added);
  CHECK(added.error().find("cannot watch /nonexistent-pitwall-folder/race.lua") == 0);
  CHECK(added.error().find("No such file or directory") != std::string::npos);
}
