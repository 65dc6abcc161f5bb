#include "engine/standings/race_json.hpp"

#include <cmath>
#include <set>

#include "engine/laps/trace_json.hpp"

namespace pitwall::standings {

namespace {

nlohmann::json orNull(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

// What a value is, for a sentence: a scalar as JSON (cut at 60 bytes), a list or an object by
// its kind (never dumped whole: it may be nested a million deep).
std::string shown(const nlohmann::json& v) {
  if (v.is_array()) return "a list";
  if (v.is_object()) return "an object";
  return v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).substr(0, 60);
}

// The field `key` of `j` as T, absent or null → `fallback`; a value of another type is an error.
// An int is a whole number of at most 2^31 − 1 either way.
template <class T>
Result<T, std::string> field(const nlohmann::json& j, const char* key, T fallback,
                             const std::string& where) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return fallback;
  bool ok = false;
  if constexpr (std::is_same_v<T, std::string>)
    ok = it->is_string();
  else if constexpr (std::is_same_v<T, bool>)
    ok = it->is_boolean();
  else if constexpr (std::is_same_v<T, int>)
    ok = it->is_number() && std::isfinite(it->get<double>()) &&
         std::fabs(it->get<double>()) <= 2147483647.0 &&
         it->get<double>() == std::floor(it->get<double>());
  else
    ok = it->is_number() && std::isfinite(it->get<double>());
  if (!ok)
    return Unexpected{where + "." + key + " must be " +
                      (std::is_same_v<T, std::string> ? "a string"
                       : std::is_same_v<T, bool>      ? "true or false"
                       : std::is_same_v<T, int>       ? "a whole number up to 2147483647"
                                                      : "a finite number") +
                      ", got " + shown(*it)};
  return it->get<T>();
}

Result<std::optional<double>, std::string> time(const nlohmann::json& j, const char* key,
                                                const std::string& where) {
  if (!j.contains(key) || j[key].is_null()) return std::optional<double>();
  auto v = field<double>(j, key, 0, where);
  if (!v) return Unexpected{v.error()};
  return std::optional<double>(*v);
}

}  // namespace

nlohmann::json toJson(const Race& race) {
  nlohmann::json entries = nlohmann::json::array();
  for (const Entry& e : race.entries)
    entries.push_back({{"number", e.number},
                       {"driver", e.driver},
                       {"car", e.car},
                       {"file", e.file},
                       {"position", e.position ? nlohmann::json(*e.position) : nullptr},
                       {"finished", e.finished},
                       {"status", e.status},
                       {"reason", e.reason},
                       {"laps", e.laps},
                       {"bestLap", orNull(e.bestLap)},
                       {"totalTime", orNull(e.totalTime)},
                       {"lapTimes", e.lapTimes}});
  for (std::size_t k = 0; k < race.entries.size(); ++k)
    if (const auto& t = race.entries[k].bestTrace)
      entries[k]["bestTrace"] = nlohmann::json::parse(t->json, nullptr, false);
  nlohmann::json j = {{"kind", race.kind},
                      {"number", race.number},
                      {"track", race.track},
                      {"laps", race.laps},
                      {"entries", entries}};
  if (!race.layout.empty()) j["layout"] = race.layout;
  return j;
}

Result<Race, std::string> raceFromJson(const nlohmann::json& j) {
  if (!j.is_object()) return Unexpected{std::string("a race must be an object")};
  Race race;
  auto kind = field<std::string>(j, "kind", "race", "race");
  auto number = field<int>(j, "number", 1, "race");
  auto track = field<std::string>(j, "track", "unknown", "race");
  auto laps = field<int>(j, "laps", 0, "race");
  if (!kind) return Unexpected{kind.error()};
  if (!number) return Unexpected{number.error()};
  if (!track) return Unexpected{track.error()};
  if (!laps) return Unexpected{laps.error()};
  race.kind = *kind;
  race.number = *number;
  race.track = *track;
  race.laps = *laps;
  if (auto it = j.find("layout"); it != j.end() && !it->is_null()) {
    if (!it->is_string()) return Unexpected{std::string("race.layout must be a layout's text")};
    race.layout = it->get<std::string>();
  }
  static const nlohmann::json kNone = nlohmann::json::array();
  const auto found = j.find("entries");
  const nlohmann::json& entries = found == j.end() || found->is_null() ? kNone : *found;
  if (!entries.is_array()) return Unexpected{std::string("race.entries must be a list")};
  std::set<int> numbers;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const auto& x = entries[k];
    const std::string where = "race.entries[" + std::to_string(k + 1) + "]";
    if (!x.is_object()) return Unexpected{where + " must be an object"};
    Entry e;
    auto n = field<int>(x, "number", static_cast<int>(k + 1), where);
    auto car = field<std::string>(x, "car", "", where);
    auto driver = field<std::string>(x, "driver", "", where);
    auto file = field<std::string>(x, "file", "", where);
    auto finished = field<bool>(x, "finished", false, where);
    auto status = field<std::string>(x, "status", "", where);
    auto reason = field<std::string>(x, "reason", "", where);
    auto lapCount = field<int>(x, "laps", 0, where);
    auto best = time(x, "bestLap", where);
    auto total = time(x, "totalTime", where);
    for (const std::string* problem :
         {n ? nullptr : &n.error(), car ? nullptr : &car.error(),
          driver ? nullptr : &driver.error(), file ? nullptr : &file.error(),
          finished ? nullptr : &finished.error(), status ? nullptr : &status.error(),
          reason ? nullptr : &reason.error(), lapCount ? nullptr : &lapCount.error(),
          best ? nullptr : &best.error(), total ? nullptr : &total.error()})
      if (problem) return Unexpected{*problem};
    e.number = *n;
    e.car = *car;
    e.driver = driver->empty() ? *car : *driver;
    if (e.driver.empty()) return Unexpected{where + " names no driver and no car"};
    e.file = *file;
    e.finished = *finished;
    e.status = status->empty() ? (e.finished ? "finished" : "DNF") : *status;
    e.reason = *reason;
    e.laps = *lapCount;
    e.bestLap = *best;
    e.totalTime = *total;
    if (x.contains("position") && !x["position"].is_null()) {
      auto p = field<int>(x, "position", 0, where);
      if (!p) return Unexpected{p.error()};
      // a place in this race: 1 … its entries
      if (*p < 1 || *p > static_cast<int>(entries.size()))
        return Unexpected{where + ".position must be a place from 1 to " +
                          std::to_string(entries.size()) + " (the race's entries), got " +
                          std::to_string(*p)};
      e.position = *p;
    }
    if (auto it = x.find("lapTimes"); it != x.end() && !it->is_null()) {
      if (!it->is_array()) return Unexpected{where + ".lapTimes must be a list of seconds"};
      for (const auto& t : *it) {
        if (!t.is_number() || !std::isfinite(t.get<double>()))
          return Unexpected{where + ".lapTimes must be a list of seconds, got " + shown(t)};
        e.lapTimes.push_back(t.get<double>());
      }
    }
    if (auto it = x.find("bestTrace"); it != x.end() && !it->is_null()) {
      auto trace = laps::traceFromJson(*it);
      if (!trace) return Unexpected{where + ".bestTrace: " + trace.error()};
      e.bestTrace = Entry::Trace{trace->time, it->dump()};  // (as it came: it reads back the same)
    }
    if (!numbers.insert(e.number).second)
      return Unexpected{where + ".number " + std::to_string(e.number) +
                        " is another entry's: each car is in a race once"};
    race.entries.push_back(std::move(e));
  }
  return race;
}

nlohmann::json toJson(const Event& e) {
  return {{"kind", e.kind},
          {"title", e.title},
          {"track", e.track},
          {"details", nlohmann::json::parse(e.details, nullptr, false)}};
}

Result<Event, std::string> eventFromJson(const nlohmann::json& j) {
  if (!j.is_object()) return Unexpected{std::string("an event must be an object")};
  Event e;
  auto kind = field<std::string>(j, "kind", "race", "event");
  auto title = field<std::string>(j, "title", "", "event");
  auto track = field<std::string>(j, "track", "unknown", "event");
  if (!kind) return Unexpected{kind.error()};
  if (!title) return Unexpected{title.error()};
  if (!track) return Unexpected{track.error()};
  e.kind = *kind;
  e.title = *title;
  e.track = *track;
  if (auto it = j.find("details"); it != j.end() && it->is_object()) e.details = it->dump();
  return e;
}

}  // namespace pitwall::standings
