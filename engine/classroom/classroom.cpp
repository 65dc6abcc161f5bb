#include "engine/classroom/classroom.hpp"

#include <sys/random.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

namespace pitwall::classroom {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kTokenBytes = 16;

// Equal without telling how much of it matched by how long it took.
bool sameSecret(std::string_view a, std::string_view b) {
  if (a.size() != b.size() || a.empty()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::string kib(std::size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f KiB", static_cast<double>(bytes) / 1024);
  return text;
}

// Characters of UTF-8 text (the JSON it came in was valid UTF-8).
std::size_t characters(std::string_view s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (c & 0xC0) != 0x80; }));
}

}  // namespace

std::string newToken() {
  unsigned char bytes[kTokenBytes];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n > 0) got += static_cast<std::size_t>(n);
  }
  std::string hex;
  char two[3];
  for (unsigned char b : bytes) {
    std::snprintf(two, sizeof two, "%02x", b);
    hex += two;
  }
  return hex;
}

Classroom::Classroom(Loop& loop, fs::path folder, std::string starter, Limits limits)
    : loop_(loop),
      folder_(std::move(folder)),
      starter_(std::move(starter)),
      limits_(limits),
      teacher_(newToken()) {}

Result<bool, std::string> Classroom::prepare() {
  std::error_code ec;
  folder_ = fs::absolute(folder_, ec).lexically_normal();
  fs::create_directories(folder_, ec);
  if (ec || !fs::is_directory(folder_))
    return Unexpected{"--code " + folder_.string() + ": cannot make the folder (" +
                      (ec ? ec.message() : std::string("a file is in its place")) +
                      "): give a folder you may write"};
  const fs::path probe = folder_ / ".pitwall-probe";
  {
    std::ofstream f(probe);
    f << "probe\n";
    if (!f)
      return Unexpected{"--code " + folder_.string() +
                        ": cannot write in it: give a folder you may write"};
  }
  fs::remove(probe, ec);
  return true;
}

fs::path Classroom::driverFile(int car) const {
  return folder_ / ("car-" + std::to_string(car)) / "driver.lua";
}

fs::path Classroom::testFile(int car) const {
  return folder_ / ("car-" + std::to_string(car)) / "test" / "driver.lua";
}

Result<bool, std::string> Classroom::addDesk(int car, std::string name) {
  const fs::path dir = folder_ / ("car-" + std::to_string(car));
  std::error_code ec;
  fs::create_directories(dir / "history", ec);
  if (!ec) fs::create_directories(dir / "test", ec);
  if (ec) return Unexpected{"--code: cannot make " + dir.string() + ": " + ec.message()};
  Desk& d = desks_[car];
  d.car = car;
  d.carName = std::move(name);
  // an earlier lesson's saves go on from their number
  for (const auto& entry : fs::directory_iterator(dir / "history", ec)) {
    const std::string stem = entry.path().stem().string();
    if (entry.path().extension() != ".lua" || stem.empty() ||
        !std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
        stem.size() > 6)
      continue;
    d.version = std::max(d.version, std::stoi(stem));
  }
  if (!fs::exists(driverFile(car), ec)) {
    if (auto written = writeFile(driverFile(car), starter_); !written)
      return Unexpected{"--code: " + written.error().why};
  }
  return true;
}

bool Classroom::isTeacher(std::string_view token) const {
  return sameSecret(token, teacher_);
}

Desk* Classroom::byToken(std::string_view token) {
  Desk* found = nullptr;
  for (auto& [car, d] : desks_)  // every desk compared: the time tells nothing of which
    if (sameSecret(token, d.token)) found = &d;
  if (found) found->lastSeen = loop_.seconds();
  return found;
}

Desk* Classroom::byCar(int car) {
  auto it = desks_.find(car);
  return it == desks_.end() ? nullptr : &it->second;
}

Result<std::string, Refusal> Classroom::join(int car, std::string_view name, std::string device) {
  Desk* d = byCar(car);
  if (!d) {
    std::string cars;
    for (const auto& [n, desk] : desks_) cars += (cars.empty() ? "" : ", ") + std::to_string(n);
    return Unexpected{Refusal{
        404, "there is no car " + std::to_string(car) + " in this lesson: pick one of " + cars}};
  }
  while (!name.empty() && name.front() == ' ') name.remove_prefix(1);
  while (!name.empty() && name.back() == ' ') name.remove_suffix(1);
  if (name.empty()) return Unexpected{Refusal{400, "give your name (it is shown to the teacher)"}};
  if (characters(name) > limits_.maxName)
    return Unexpected{Refusal{400, "your name has " + std::to_string(characters(name)) +
                                       " characters: give at most " +
                                       std::to_string(limits_.maxName)}};
  // control characters, and the bidi overrides (U+202A–202E, U+2066–2069) that would show a
  // name reversed on the teacher's table
  static constexpr std::string_view kBidi[] = {"\xE2\x80\xAA", "\xE2\x80\xAB", "\xE2\x80\xAC",
                                               "\xE2\x80\xAD", "\xE2\x80\xAE", "\xE2\x81\xA6",
                                               "\xE2\x81\xA7", "\xE2\x81\xA8", "\xE2\x81\xA9"};
  const bool bidi = std::any_of(std::begin(kBidi), std::end(kBidi), [&](std::string_view b) {
    return name.find(b) != std::string_view::npos;
  });
  if (bidi || std::any_of(name.begin(), name.end(),
                          [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
    return Unexpected{Refusal{400, "your name has a control character: give letters and spaces"}};
  if (!d->token.empty())
    return Unexpected{Refusal{409, "car " + std::to_string(car) + " is taken by " + d->student +
                                       ": pick a free car, or ask the teacher to free it"}};
  if (!device.empty())
    for (const auto& [n, other] : desks_)
      if (!other.token.empty() && other.device == device)
        return Unexpected{Refusal{409, "this device holds car " + std::to_string(n) +
                                           " already (one car a device): ask the teacher to "
                                           "give you another, or to free it"}};
  d->student = std::string(name);
  d->device = std::move(device);
  d->token = newToken();
  d->lastSeen = loop_.seconds();
  return d->token;
}

bool Classroom::free(int car) {
  Desk* d = byCar(car);
  if (!d || d->token.empty()) return false;
  d->token.clear();
  d->student.clear();
  d->device.clear();
  d->testing = false;  // (a test of the student who left answers them, not the next)
  return true;
}

Result<std::string, Refusal> Classroom::read(const Desk& d) const {
  std::ifstream f(driverFile(d.car), std::ios::binary);
  if (!f) return Unexpected{Refusal{500, "cannot read " + driverFile(d.car).string()}};
  std::ostringstream text;
  text << f.rdbuf();
  return text.str();
}

Result<bool, Refusal> Classroom::writeFile(const fs::path& path, std::string_view text) const {
  // written beside, then renamed: a driver world loading it never reads half a file
  const fs::path tmp = path.string() + ".saving";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!f)
      return Unexpected{Refusal{507, "cannot write " + path.string() + " (is the disk full?)"}};
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) return Unexpected{Refusal{507, "cannot write " + path.string() + ": " + ec.message()}};
  return true;
}

Result<SaveResult, Refusal> Classroom::save(Desk& d, std::string_view text) {
  if (locked_)
    return Unexpected{Refusal{423,
                              "the teacher has locked the editors: your text is not saved "
                              "(keep it; save when they unlock)"}};
  if (text.size() > limits_.maxFile)
    return Unexpected{Refusal{413, "the file is " + kib(text.size()) + ": a driver may be " +
                                       kib(limits_.maxFile) + " at most"}};
  if (!d.saveBucket.take(limits_.saves, loop_.now()))
    return Unexpected{Refusal{429,
                              "too many saves at once: wait a few seconds and save again "
                              "(your text is still in the editor)"}};
  const fs::path dir = driverFile(d.car).parent_path();
  const int version = d.version + 1;
  if (auto w = writeFile(dir / "history" / (std::to_string(version) + ".lua"), text); !w)
    return Unexpected{w.error()};
  if (auto w = writeFile(driverFile(d.car), text); !w) return Unexpected{w.error()};
  d.version = version;
  d.saves++;
  // the oldest beyond the last `history` go
  if (version > static_cast<int>(limits_.history)) {
    std::error_code ec;
    fs::remove(
        dir / "history" / (std::to_string(version - static_cast<int>(limits_.history)) + ".lua"),
        ec);
  }
  SaveResult r;
  r.version = version;
  if (d.driver) {
    r.raceOn = true;
    std::string why;
    r.driving = d.driver->trySave(why);
    if (!r.driving) {
      r.error = why;
      r.line = lineOf(why);
    }
  }
  d.lastError = r.error;
  return r;
}

Result<fs::path, Refusal> Classroom::prepareTest(Desk& d, std::string_view text) {
  if (d.testing)
    return Unexpected{Refusal{409, "your last test is still running: wait for its result"}};
  if (text.size() > limits_.maxFile)
    return Unexpected{Refusal{413, "the file is " + kib(text.size()) + ": a driver may be " +
                                       kib(limits_.maxFile) + " at most"}};
  if (!d.testBucket.take(limits_.tests, loop_.now()))
    return Unexpected{Refusal{429, "too many tests at once: wait a few seconds and test again"}};
  if (auto w = writeFile(testFile(d.car), text); !w) return Unexpected{w.error()};
  return testFile(d.car);
}

std::vector<HistoryEntry> Classroom::history(const Desk& d) const {
  std::vector<HistoryEntry> out;
  const fs::path dir = driverFile(d.car).parent_path() / "history";
  const auto now = fs::file_time_type::clock::now();
  for (int v = d.version; v >= 1 && out.size() < limits_.history; --v) {
    std::error_code ec;
    const fs::path p = dir / (std::to_string(v) + ".lua");
    auto bytes = fs::file_size(p, ec);
    if (ec) continue;
    auto when = fs::last_write_time(p, ec);
    out.push_back({v, static_cast<std::size_t>(bytes),
                   ec ? 0 : std::chrono::duration<double>(now - when).count()});
  }
  return out;
}

Result<std::string, Refusal> Classroom::version(const Desk& d, int v) const {
  const fs::path p = driverFile(d.car).parent_path() / "history" / (std::to_string(v) + ".lua");
  std::ifstream f(p, std::ios::binary);
  if (v < 1 || v > d.version || !f)
    return Unexpected{Refusal{404, "there is no save " + std::to_string(v) + " of car " +
                                       std::to_string(d.car) + " (its saves are 1 to " +
                                       std::to_string(d.version) + ", the oldest dropped)"}};
  std::ostringstream text;
  text << f.rdbuf();
  return text.str();
}

fs::path Classroom::leagueFolder(int number) const {
  return folder_ / "leagues" / std::to_string(number);
}

Result<Classroom::League, Refusal> Classroom::prepareLeague() {
  League league;
  std::error_code ec;
  for (league.number = 1; fs::exists(leagueFolder(league.number), ec); ++league.number) {
  }
  league.folder = leagueFolder(league.number);
  fs::create_directories(league.folder, ec);
  if (ec)
    return Unexpected{Refusal{507, "cannot make " + league.folder.string() + ": " + ec.message()}};
  for (const auto& [car, d] : desks_) {
    // the league names a driver by its file: the car, and the student's name in letters and
    // digits (nothing of it reaches a path but those)
    std::string name = "car-" + std::to_string(car);
    std::string slug;
    for (char c : d.student)
      if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'))
        slug += c;
      else if (c >= 'A' && c <= 'Z')
        slug += static_cast<char>(c - 'A' + 'a');
    if (!slug.empty()) name += "-" + slug.substr(0, 20);
    const fs::path copy = league.folder / (name + ".lua");
    fs::copy_file(driverFile(car), copy, fs::copy_options::overwrite_existing, ec);
    if (ec)
      return Unexpected{
          Refusal{507, "cannot copy " + driverFile(car).string() + ": " + ec.message()}};
    league.files.push_back(copy);
  }
  if (league.files.size() < 2) return Unexpected{Refusal{409, "a league needs 2 desks at least"}};
  return league;
}

std::optional<int> Classroom::takeStart() {
  auto s = start_;
  start_.reset();
  return s;
}

Result<std::string, Refusal> Classroom::reset(int car) {
  Desk* d = byCar(car);
  if (!d) return Unexpected{Refusal{404, "there is no car " + std::to_string(car)}};
  if (!d->driver)
    return Unexpected{Refusal{409, "no race drives car " + std::to_string(car) +
                                       " now: its driver starts with the next one"}};
  std::string why;
  if (!d->driver->restart(why)) return Unexpected{Refusal{422, why}};
  return "car " + std::to_string(car) + "'s driver starts again from its file";
}

void Classroom::attach(int car, DeskDriver* driver) {
  if (Desk* d = byCar(car)) d->driver = driver;
}

void Classroom::detach(int car, DeskDriver* driver) {
  if (Desk* d = byCar(car); d && d->driver == driver) d->driver = nullptr;
}

nlohmann::json Classroom::status() const {
  nlohmann::json desks = nlohmann::json::array();
  const double now = loop_.seconds();
  for (const auto& [car, d] : desks_) {
    nlohmann::json j = {{"car", car},
                        {"carName", d.carName},
                        {"student", d.student},
                        {"joined", !d.token.empty()},
                        {"saves", d.saves},
                        {"version", d.version},
                        {"raceOn", d.driver != nullptr},
                        {"lastError", d.lastError}};
    j["seen"] = d.lastSeen < 0 ? nlohmann::json(nullptr) : nlohmann::json(now - d.lastSeen);
    j["failure"] = d.driver ? d.driver->whyOut() : std::string();
    desks.push_back(std::move(j));
  }
  return {{"desks", desks}, {"locked", locked_}};
}

int Classroom::lineOf(std::string_view s) {
  static constexpr std::string_view kName = "driver.lua:";
  for (auto at = s.find(kName); at != std::string_view::npos; at = s.find(kName, at + 1)) {
    std::size_t i = at + kName.size();
    int line = 0;
    std::size_t digits = 0;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9' && digits < 7) {
      line = line * 10 + (s[i] - '0');
      ++i;
      ++digits;
    }
    if (digits > 0 && i < s.size() && s[i] == ':') return line;
  }
  return 0;
}

}  // namespace pitwall::classroom
