#pragma once
// Watches script files for changes on the engine loop (inotify), for hot reload (issue 5:
// `pitwall run --watch`). The folders of the files are watched, not the files, so that editors'
// atomic saves (write a temporary file, rename it over the original) and backup-and-rewrite
// saves are both seen. Changes are debounced: the callback runs once the watched files have been
// quiet for the debounce time, with every file that changed meanwhile.
#include <boost/asio/posix/stream_descriptor.hpp>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"

namespace pitwall {

class FileWatch {
 public:
  using Changed = std::function<void(const std::vector<std::string>& paths)>;

  // Throws std::runtime_error when inotify cannot be had (too many instances, no kernel support).
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
  void waitForEvents();
  void readEvents();
  void changed(const std::string& path);

  Loop& loop_;
  Duration debounce_;
  boost::asio::posix::stream_descriptor fd_;
  std::map<int, std::string> folders_;                  // watch descriptor → folder
  std::map<std::string, std::set<std::string>> names_;  // folder → names watched in it
  std::set<std::string> pending_;
  Loop::TimerId quiet_ = 0;
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall
