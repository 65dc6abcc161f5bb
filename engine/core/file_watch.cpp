#include "engine/core/file_watch.hpp"

#include <sys/inotify.h>

#include <filesystem>
#include <stdexcept>

namespace pitwall {

namespace fs = std::filesystem;

namespace {
// What a save looks like from the folder: the file written and closed, a file renamed onto its
// name, created, written, or (a backup-and-rewrite editor) moved away and deleted before the new
// one is written.
constexpr std::uint32_t kMask =
    IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_MODIFY | IN_DELETE | IN_MOVED_FROM | IN_ATTRIB;
// A complete save: the content is all there, whichever way the editor saved.
constexpr std::uint32_t kSaved = IN_CLOSE_WRITE | IN_MOVED_TO;
}  // namespace

FileWatch::FileWatch(Loop& loop, Duration debounce)
    : loop_(loop), debounce_(debounce), alive_(std::make_shared<bool>(true)) {
  auto made = Inotify::open(loop);
  if (!made) throw std::runtime_error("cannot watch files: " + made.error());
  inotify_ = std::move(made).value();
  inotify_->onEvent = [this](int wd, std::uint32_t mask, const std::string& name) {
    event(wd, mask, name);
  };
  inotify_->onOverflow = [this] { overflowed(); };
}

FileWatch::~FileWatch() {
  *alive_ = false;
  loop_.cancel(quiet_);
}

Result<bool, std::string> FileWatch::add(const std::string& file) {
  std::error_code ec;
  fs::path path = fs::absolute(file, ec).lexically_normal();
  if (ec) return Unexpected{"cannot watch " + file + ": " + ec.message()};
  std::string folder = path.parent_path().string();
  if (!names_.count(folder)) {
    auto wd = inotify_->add(folder, kMask);
    if (!wd)
      return Unexpected{"cannot watch " + file + ": its folder " + folder + ": " + wd.error()};
    folders_[*wd] = folder;
  }
  names_[folder].insert(path.filename().string());
  return true;
}

std::vector<std::string> FileWatch::files() const {
  std::vector<std::string> out;
  for (const auto& [folder, names] : names_)
    for (const auto& n : names) out.push_back((fs::path(folder) / n).string());
  return out;
}

// The kernel's queue overflowed (a flood of changes in a watched folder): events were lost, a save
// among them perhaps. Every watched file is taken as changed, after quiet.
void FileWatch::overflowed() {
  for (const auto& [folder, names] : names_)
    for (const auto& name : names) changed((fs::path(folder) / name).string(), IN_MODIFY);
}

void FileWatch::event(int wd, std::uint32_t mask, const std::string& name) {
  if (name.empty()) return;
  auto folder = folders_.find(wd);
  if (folder == folders_.end() || !names_[folder->second].count(name)) return;
  // A complete save is the leading edge of a burst: reported on the next turn of the loop, with
  // everything this read of the queue brought (the read goes on until the queue is empty before
  // the loop turns). Within a burst, saves wait for the end of the window.
  if (changed((fs::path(folder->second) / name).string(), mask) && !inBurst_ && !reportPosted_) {
    reportPosted_ = true;
    std::weak_ptr<bool> alive = alive_;
    loop_.post([this, alive] {
      if (!alive.expired()) reportAtOnce();
    });
  }
}

bool FileWatch::changed(const std::string& path, std::uint32_t mask) {
  // An editor that sets the file's mode after its save: nothing new about the content just
  // reported, and not worth a second reload.
  if (inBurst_ && (mask & kMask) == IN_ATTRIB) return false;
  pending_.insert(path);
  armQuiet();
  return (mask & kSaved) != 0;
}

void FileWatch::armQuiet() {
  loop_.cancel(quiet_);
  std::weak_ptr<bool> alive = alive_;
  quiet_ = loop_.after(debounce_, [this, alive] {
    if (alive.expired()) return;
    quiet_ = 0;
    inBurst_ = false;  // the files have been quiet for a whole window: the burst is over
    auto ready = takeReady();
    if (!ready.empty() && onChange) onChange(ready);  // last: it may end this watch
  });
}

void FileWatch::reportAtOnce() {
  reportPosted_ = false;
  auto ready = takeReady();
  if (ready.empty()) return;
  inBurst_ = true;  // what follows within the window is one more report, at its end
  armQuiet();
  if (onChange) onChange(ready);  // last: it may end this watch
}

std::vector<std::string> FileWatch::takeReady() {
  std::vector<std::string> ready;
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (fs::exists(*it)) {
      ready.push_back(*it);
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
  return ready;
}

}  // namespace pitwall
