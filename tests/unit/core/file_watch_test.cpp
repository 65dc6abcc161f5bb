// Watching script files for hot reload: real files in a scratch folder, a real-clock loop.
#include "engine/core/file_watch.hpp"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include "tests/support/run_until.hpp"
#include "tests/support/temp_dir.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {
struct Folder {
  testing::TempDir temp{"pitwall-watch"};
  fs::path dir = temp.path;
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

// A watch with a burst window of `window`, reports kept with what the reported files held at the
// time (what a reload would have loaded) and the loop's time.
struct Watching {
  Loop loop{ClockKind::Real};
  Folder folder;
  FileWatch watch;
  struct Report {
    std::vector<std::string> paths;
    std::vector<std::string> texts;
    TimePoint at;
  };
  std::vector<Report> reports;
  explicit Watching(Duration window = 30ms) : watch(loop, window) {
    watch.onChange = [this](const std::vector<std::string>& paths) {
      Report r{paths, {}, loop.now()};
      for (const auto& p : paths) {
        std::ifstream in(p);
        r.texts.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      }
      reports.push_back(std::move(r));
    };
  }
  bool reported(std::size_t n) {
    return testing::runUntil(
        loop, [&] { return reports.size() >= n; }, 5s);
  }
};

// A window no test can wait out: a report that comes at all did not wait for it.
struct WatchingHourWindow : Watching {
  WatchingHourWindow() : Watching(1h) {}
};
}  // namespace

TEST_CASE_FIXTURE(WatchingHourWindow,
                  "a file written in place is reported at once, not after the window") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  loop.post([&] { folder.write("race.lua", "print(2)"); });
  REQUIRE(reported(1));
  CHECK(reports[0].paths == std::vector<std::string>{script});
  CHECK(reports[0].texts[0] == "print(2)");
  CHECK(reports[0].at < 1h);
}

TEST_CASE_FIXTURE(
    WatchingHourWindow,
    "an editor's atomic save (write a temporary file, rename it over) is reported at once") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  loop.post([&] {
    auto tmp = folder.write(".race.lua.swp", "print(2)");
    fs::rename(tmp, script);
  });
  REQUIRE(reported(1));
  CHECK(reports[0].paths == std::vector<std::string>{script});
  CHECK(reports[0].texts[0] == "print(2)");
}

TEST_CASE_FIXTURE(WatchingHourWindow,
                  "a backup-and-rewrite save is reported at once when the new file is written") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  loop.post([&] {
    fs::rename(script, folder.dir / "race.lua~");
    // The rewrite comes on a later turn of the loop: the file is missing meanwhile.
    loop.post([&] { folder.write("race.lua", "print(2)"); });
  });
  REQUIRE(reported(1));
  CHECK(reports[0].paths == std::vector<std::string>{script});
  CHECK(reports[0].texts[0] == "print(2)");
}

TEST_CASE_FIXTURE(WatchingHourWindow,
                  "a file being written is not reported until it is closed: no half-written file") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  std::FILE* f = nullptr;
  bool closed = false;
  loop.post([&] {
    f = std::fopen(script.c_str(), "w");
    std::fputs("print(", f);
    std::fflush(f);  // written, not closed: IN_MODIFY only
    loop.after(20ms, [&] {
      std::fputs("2)", f);
      closed = true;
      std::fclose(f);
    });
  });
  REQUIRE(reported(1));
  CHECK(closed);
  CHECK(reports[0].texts[0] == "print(2)");
}

TEST_CASE("a file written and left open is reported once the files were quiet for the window") {
  Watching w(150ms);
  auto script = w.folder.write("race.lua", "print(1)");
  REQUIRE(w.watch.add(script));
  std::FILE* f = nullptr;
  TimePoint wrote{};
  w.loop.post([&] {
    f = std::fopen(script.c_str(), "w");
    std::fputs("print(2)", f);
    std::fflush(f);
    wrote = w.loop.now();
  });
  REQUIRE(w.reported(1));
  CHECK(w.reports[0].at - wrote >= 150ms);  // the window, measured on the loop's own clock
  CHECK(w.reports[0].texts[0] == "print(2)");
  // Closing it is a complete save: reported again.
  std::fclose(f);
  REQUIRE(w.reported(2));
  CHECK(w.reports[1].paths == std::vector<std::string>{script});
}

TEST_CASE("a burst of saves is reported twice: at its first save and once it is over") {
  Watching w(400ms);
  auto script = w.folder.write("race.lua", "print(0)");
  REQUIRE(w.watch.add(script));
  w.loop.post([&] { w.folder.write("race.lua", "print(1)"); });
  REQUIRE(w.reported(1));  // the first save, at once
  CHECK(w.reports[0].texts[0] == "print(1)");
  // Nine more saves, each on a turn of the loop of its own, within the window.
  int saves = 1;
  std::function<void()> save = [&] {
    w.folder.write("race.lua", "print(" + std::to_string(++saves) + ")");
    if (saves < 10) w.loop.post(save);
  };
  w.loop.post(save);
  REQUIRE(w.reported(2));
  CHECK(saves == 10);
  CHECK(w.reports[1].texts[0] == "print(10)");        // the last save is the one loaded
  CHECK(w.reports[1].at - w.reports[0].at >= 400ms);  // at the end of the window
  testing::runFor(w.loop, 100ms);
  CHECK(w.reports.size() == 2);
}

TEST_CASE_FIXTURE(Watching, "an editor's chmod after its save does not make a second report") {
  auto a = folder.write("a.lua", "1");
  auto b = folder.write("b.lua", "1");
  REQUIRE(watch.add(a));
  REQUIRE(watch.add(b));
  loop.post([&] { folder.write("a.lua", "2"); });
  REQUIRE(reported(1));
  CHECK(reports[0].paths == std::vector<std::string>{a});
  loop.post([&] {
    fs::permissions(a, fs::perms::owner_exec, fs::perm_options::add);  // IN_ATTRIB alone
    folder.write("b.lua", "2");  // within the window: reported at its end
  });
  REQUIRE(reported(2));
  CHECK(reports[1].paths == std::vector<std::string>{b});
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
  CHECK(reports[0].paths.size() == 2);  // one read brought both saves: one report
}

TEST_CASE_FIXTURE(Watching, "a save lost in an overflow of the kernel's queue is still reported") {
  auto script = folder.write("race.lua", "print(1)");
  REQUIRE(watch.add(script));
  long queue = 16384;
  std::ifstream("/proc/sys/fs/inotify/max_queued_events") >> queue;
  // More changes in the folder than the kernel queues (two events a write: modify, close), then
  // the save, whose events are lost in the overflow. Written before the loop runs (nothing reads
  // the queue meanwhile), so the wait below is for the report alone, however slow the writes on
  // a loaded machine.
  for (long i = 0; i < queue / 2 + 100; ++i) folder.write("noise.txt", std::to_string(i));
  folder.write("race.lua", "print(2)");
  REQUIRE(testing::runUntil(
      loop, [&] { return !reports.empty(); }, 30s));
  CHECK(reports[0].paths == std::vector<std::string>{script});
  CHECK(reports[0].texts[0] == "print(2)");
}

TEST_CASE("a file in a folder that does not exist is refused with the reason") {
  Loop loop{ClockKind::Real};
  FileWatch watch{loop};
  auto added = watch.add("/nonexistent-pitwall-folder/race.lua");
  REQUIRE_FALSE(added);
  CHECK(added.error().find("cannot watch /nonexistent-pitwall-folder/race.lua") == 0);
  CHECK(added.error().find("No such file or directory") != std::string::npos);
}
