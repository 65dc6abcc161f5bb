#pragma once
// Watches script files for changes on the engine loop (inotify), for hot reload (issue 5:
// `pitwall run --watch`). The folders of the files are watched, not the files, so that editors'
// atomic saves (write a temporary file, rename it over the original) and backup-and-rewrite
// saves are both seen.
//
// A complete save — a watched file written and closed, or a file renamed onto a watched name —
// is reported at once, on the next turn of the loop, with whatever else the same read of the
// inotify queue brought (issue 14: save → new handlers in a few ms). Only bursts are debounced:
// what changes within the debounce window after a report is collected and reported once more
// when the files have been quiet for the window, so a burst of saves makes at most two reports.
// Changes that are not a complete save (written but not closed yet, created, deleted, moved
// away, attributes changed) are reported only once the files have been quiet for the window, so
// a half-written file is not loaded.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "engine/core/inotify.hpp"
#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"

namespace pitwall {

class FileWatch {
 public:
  using Changed = std::function<void(const std::vector<std::string>& paths)>;

  // `debounce` is the burst window (above). Throws std::runtime_error when inotify cannot be had
  // (too many instances, no kernel support).
  FileWatch(Loop& loop, Duration debounce = std::chrono::milliseconds(100));
  ~FileWatch();
  FileWatch(const FileWatch&) = delete;
  FileWatch& operator=(const FileWatch&) = delete;

  // Watches `file` (made absolute); an error names the file and the reason (no such folder, …).
  Result<bool, std::string> add(const std::string& file);
  // The files being watched, absolute.
  std::vector<std::string> files() const;

  Changed onChange;

 private:
  void event(int wd, std::uint32_t mask, const std::string& name);
  void overflowed();
  // One inotify event on a watched file; true when it is a complete save.
  bool changed(const std::string& path, std::uint32_t mask);
  void armQuiet();
  void reportAtOnce();
  // Takes the pending files that exist now out of the pending set; one that is gone is in the
  // middle of a save and is reported when it is back.
  std::vector<std::string> takeReady();

  Loop& loop_;
  Duration debounce_;
  std::unique_ptr<Inotify> inotify_;
  std::map<int, std::string> folders_;                  // watch descriptor → folder
  std::map<std::string, std::set<std::string>> names_;  // folder → names watched in it
  std::set<std::string> pending_;
  Loop::TimerId quiet_ = 0;    // the end of the window: the files have been quiet for it
  bool inBurst_ = false;       // a report was made and the files have not been quiet since
  bool reportPosted_ = false;  // a complete save's report waits for the next turn of the loop
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall
