#include "engine/view/feed.hpp"

#include <algorithm>
#include <cmath>

#include "engine/core/log.hpp"
#include "engine/protocol/anki/limits.hpp"
#include "engine/view/geometry.hpp"

namespace pitwall::view {

namespace {
constexpr std::size_t kEventsKept = 200;
constexpr double kHistorySeconds = 60;
constexpr double kHistoryStep = 0.1;  // at most 10 speed samples a second
// Lap times sent per car: the latest ones (lapTimesFrom numbers the first)
constexpr std::size_t kLapsInState = 1000;
constexpr std::size_t kLapsInUpdate = 100;
// Distinct colours for markers (car 1 first); repeats after 12.
constexpr const char* kColours[] = {"#e6194b", "#3cb44b", "#ffe119", "#4363d8",
                                    "#f58231", "#911eb4", "#42d4f4", "#f032e6",
                                    "#bfef45", "#fabed4", "#469990", "#dcbeff"};

double round3(double v) {
  double r = std::round(v * 1000) / 1000;
  return r == 0 ? 0 : r;
}
}  // namespace

constexpr double kStandAfter = 0.5;  // s without a speed report after a command of speed 0

struct Feed::Car {
  laps::CarTracker tracker;
  laps::TraceBuilder traces;
  std::deque<laps::LapTrace> laps;            // its last kLapsKept laps' traces
  std::deque<std::pair<double, int>> speeds;  // (time, mm/s)
  int commanded = -1;      // the last speed sent to the car (mm/s); -1: none seen (a replay)
  double reportedAt = -1;  // feed time of its last report of its speed
  bool standing = false;   // as settle() last found it
  bool ghost = false;      // the simulator's ghost of a recorded lap
  std::string name;
};

Feed::Feed(Loop& loop, Fleet& fleet, std::string source)
    : loop_(loop), fleet_(fleet), source_(std::move(source)) {
  framesSub_ = fleet_.frames.connect([this](AnkiCar& car, AnkiCar::Direction d,
                                            std::span<const std::uint8_t>,
                                            const anki::Message& m) { frame(car, d, m); });
  connectionSub_ =
      fleet_.connectionChanged.connect([this](AnkiCar& car, bool up, const std::string& reason) {
        event(up ? "info" : "warn", car.label() + (up ? " connected" : " disconnected") +
                                        (up || reason.empty() ? "" : ": " + reason));
      });
}

Feed::~Feed() {
  followLog(false);
  seatsSub_.disconnect();
  askedSub_.disconnect();
  framesSub_.disconnect();
  connectionSub_.disconnect();
}

void Feed::followLog(bool on) {
  if (on && !logTap_) {
    logTap_ =
        log::addTap([this](log::Level level, std::string_view component, std::string_view message) {
          // warnings, errors, and what a reload says; the rest of the log stays in the terminal
          if (level < log::Level::Warn && component != "reload") return;
          event(level == log::Level::Error  ? "error"
                : level == log::Level::Warn ? "warn"
                                            : "info",
                std::string(component) + ": " + std::string(message));
        });
  } else if (!on && logTap_) {
    log::removeTap(logTap_);
    logTap_ = 0;
  }
}

Feed::Car& Feed::car(AnkiCar& car) {
  // frames come in runs from one car (cars_ is by number: a car made anew at the same address
  // with the same number has the same slot)
  const int number = car.identity().number;
  if (&car == lastAnki_ && number == lastNumber_) return *lastCar_;
  auto& slot = cars_[number];
  if (!slot) {
    slot = std::make_unique<Car>();
    slot->tracker.setTrack(track_ ? &*track_ : nullptr);
    slot->traces.setTrack(track_ ? &*track_ : nullptr);
    slot->ghost = car.identity().ghost;
    slot->name = car.identity().name;
  }
  lastAnki_ = &car;
  lastNumber_ = number;
  lastCar_ = slot.get();
  return *slot;
}

void Feed::reset() {
  cars_.clear();
  ghost_.reset();
  best_.reset();
  lastAnki_ = nullptr;
  lastCar_ = nullptr;
  ++changes_;
}

const laps::CarTracker* Feed::tracker(int number) const {
  auto it = cars_.find(number);
  return it == cars_.end() ? nullptr : &it->second->tracker;
}

std::vector<std::pair<int, std::string>> Feed::tracedCars() const {
  std::vector<std::pair<int, std::string>> out;
  for (const auto& [number, c] : cars_) out.emplace_back(number, c->name);
  return out;
}

const std::deque<laps::LapTrace>* Feed::laps(int number) const {
  auto it = cars_.find(number);
  return it == cars_.end() ? nullptr : &it->second->laps;
}

void Feed::sent(AnkiCar& ankiCar, const anki::Message& m) {
  if (auto* set = std::get_if<anki::SetSpeed>(&m)) car(ankiCar).commanded = set->speed_mm_s;
}

void Feed::frame(AnkiCar& ankiCar, AnkiCar::Direction d, const anki::Message& m) {
  if (d != AnkiCar::Direction::Rx) return sent(ankiCar, m);
  const bool moves = std::holds_alternative<anki::PositionUpdate>(m) ||
                     std::holds_alternative<anki::TransitionUpdate>(m) ||
                     std::holds_alternative<anki::Delocalized>(m) ||
                     std::holds_alternative<anki::SpeedUpdate>(m);
  if (!moves) return;
  ++changes_;
  Car& c = car(ankiCar);
  // A position update's time is in the car's state already (one clock read fewer per frame)
  const double now = !clock_ && std::holds_alternative<anki::PositionUpdate>(m)
                         ? ankiCar.state().last_position_time
                         : this->now();
  c.tracker.update(m, ankiCar.state(), now);
  if (auto lap = c.traces.update(c.tracker, m, ankiCar.state().reverse, now)) {
    if (lap->clean) {  // the reference of the live deltas: a ghost's lap, else the best lap
      const std::string label = c.name + " lap " + std::to_string(lap->lap);
      if (c.ghost)
        ghost_ = Reference{*lap, "the ghost (" + label + ")"};
      else if (!best_ || lap->time < best_->lap.time)
        best_ = Reference{*lap, "the best lap (" + label + ")"};
    }
    c.laps.push_back(std::move(*lap));
    if (c.laps.size() > kLapsKept) c.laps.pop_front();
  }
  if (std::holds_alternative<anki::PositionUpdate>(m) ||
      std::holds_alternative<anki::SpeedUpdate>(m)) {
    c.reportedAt = now;
    c.standing = false;  // it says its speed again (until then a standing car stays at 0)
  }
  if (c.speeds.empty() || now - c.speeds.back().first >= kHistoryStep) {
    c.speeds.emplace_back(now, ankiCar.state().speed_mm_s);
    while (!c.speeds.empty() && c.speeds.front().first < now - kHistorySeconds)
      c.speeds.pop_front();
  }
}

bool Feed::stands(const Car& c) const {
  return c.commanded == 0 && (c.reportedAt < 0 || now() - c.reportedAt > kStandAfter);
}

void Feed::settle() {
  for (auto& [number, c] : cars_) {
    if (c->standing || !stands(*c)) continue;
    c->standing = true;
    ++changes_;
    c->speeds.emplace_back(now(), 0);  // the speed chart comes down to 0
  }
}

void Feed::setTrack(std::optional<sim::Track> track, const std::string& source) {
  track_ = std::move(track);
  trackSource_ = track_ ? source : "none";
  ghost_.reset();  // laps of another track are no reference
  best_.reset();
  personal_.reset();
  lapMap_.reset();
  if (track_) lapMap_.emplace(*track_);
  ++trackVersion_;
  ++changes_;
  for (auto& [number, c] : cars_) {
    c->tracker.setTrack(track_ ? &*track_ : nullptr);
    c->traces.setTrack(track_ ? &*track_ : nullptr);
  }
  if (track_)
    event("info", "track: " + track_->name() + " (" + std::to_string(track_->size()) + " pieces, " +
                      source + ")");
}

void Feed::setRace(nlohmann::json race) {
  auto phaseOf = [](const nlohmann::json& r) -> std::string {
    if (!r.is_object()) return "";
    auto it = r.find("phase");
    return it != r.end() && it->is_string() ? it->get<std::string>() : "";
  };
  std::string before = phaseOf(race_), after = phaseOf(race);
  race_ = std::move(race);
  // dumped once here, not again for every update that a car's move makes
  raceText_ = race_.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  ++changes_;
  if (!after.empty() && after != before) {
    auto title = race_.find("title");
    std::string text = (title != race_.end() && title->is_string() ? title->get<std::string>()
                                                                   : std::string("race")) +
                       ": " + after;
    // a replay that moved back reports the same phases at the same times again: said once
    const double t = now();
    const bool said = std::any_of(events_.begin(), events_.end(), [&](const Event& e) {
      return e.text == text && std::abs(e.t - t) < 1e-6;
    });
    if (!said) event("info", text);
  }
}

void Feed::setSeats(drive::Seats* seats) {
  seatsSub_.disconnect();
  askedSub_.disconnect();
  seats_ = seats;
  if (seats_) {
    seatsSub_ = seats_->changed.connect([this](const drive::Seat&) { ++changes_; });
    askedSub_ = seats_->asked.connect([this](const drive::Seat&) { ++changes_; });
  }
  ++changes_;
}

void Feed::event(const std::string& level, const std::string& text) {
  events_.push_back({nextEvent_++, now(), level, text});
  ++changes_;
  while (events_.size() > kEventsKept) events_.pop_front();
}

// The link's health, as car.link has it (docs/view.md "State")
nlohmann::json linkJson(const AnkiCar& car) {
  const CarState& s = car.state();
  const LinkHealth h = car.link().health();
  return {{"connects", s.connects},
          {"drops", s.drops},
          {"lastDrop", s.last_drop.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.last_drop)},
          {"writeFailures", h.writeFailures},
          {"stalls", h.stalls},
          {"rssi", h.rssi ? nlohmann::json(*h.rssi) : nlohmann::json(nullptr)},
          {"silences", s.silences},
          {"longestSilence", round3(s.longest_silence)},
          {"roundTrip",
           s.round_trip >= 0 ? nlohmann::json(round3(s.round_trip)) : nlohmann::json(nullptr)}};
}

nlohmann::json Feed::carJson(const AnkiCar& ankiCar, std::size_t laps) const {
  const CarState& s = ankiCar.state();
  const int number = ankiCar.identity().number;
  const Car* c = nullptr;
  if (auto it = cars_.find(number); it != cars_.end()) c = it->second.get();
  nlohmann::json j = {
      {"number", number},
      {"name", ankiCar.identity().name},
      {"ghost", ankiCar.identity().ghost},
      {"color", kColours[(number - 1) % std::size(kColours)]},
      {"connected", s.connected},
      {"onTrack", s.on_track},
      {"delocalized", s.delocalized},
      {"reverse", s.reverse},
      {"piece", s.piece},
      {"location", s.location},
      {"offset", round3(s.offset_mm)},
      {"speed", s.speed_mm_s},
      {"targetSpeed", s.target_speed_mm_s},
      {"battery", s.battery_mv},
      {"framesIn", s.frames_in},
      {"framesOut", s.frames_out},
      {"malformed", s.malformed},
      {"link", linkJson(ankiCar)},
      {"pieceIndex", nullptr},
      {"fraction", nullptr},
      {"x", nullptr},
      {"y", nullptr},
      {"heading", nullptr},
      {"positionTime", s.last_position_time >= 0 ? nlohmann::json(round3(s.last_position_time))
                                                 : nlohmann::json(nullptr)},
      {"lap", 0},
      {"lapTimes", nlohmann::json::array()},
      {"lapTimesFrom", 1},
      {"lastLap", nullptr},
      {"bestLap", nullptr},
  };
  if (!c) return j;
  if (c->standing) j["speed"] = 0;
  const laps::CarTracker& t = c->tracker;
  j["lap"] = t.laps();
  // the latest `laps` of them: a long session's list does not grow every update
  const auto& all = t.lapTimes();
  const std::size_t from = all.size() > laps ? all.size() - laps : 0;
  nlohmann::json times = nlohmann::json::array();
  for (std::size_t k = from; k < all.size(); ++k) times.push_back(round3(all[k]));
  j["lapTimes"] = std::move(times);
  j["lapTimesFrom"] = from + 1;
  if (!all.empty()) {
    j["lastLap"] = round3(all.back());
    j["bestLap"] = round3(*t.bestLap());
  }
  if (track_ && t.pieceIndex() && !s.delocalized && s.on_track) {
    // localized: moved on from the last position or transition by the car's speed (the page
    // goes on from here between updates)
    const double at = std::max(now(), t.positionTime());
    const double fraction = t.fractionAt(at, s.speed_mm_s, s.offset_mm, s.reverse);
    Pose p = pointOnTrack(*track_, *t.pieceIndex(), fraction, s.offset_mm);
    j["pieceIndex"] = *t.pieceIndex();
    j["fraction"] = round3(fraction);
    j["x"] = round3(p.x);
    j["y"] = round3(p.y);
    j["heading"] = round3(p.heading);
    j["positionTime"] = round3(t.positionTime());
    j["at"] = round3(at);
    // the live delta to the reference lap, at the distance the car has come this lap
    const Reference* ref = reference();
    const laps::LapTrace* lap = c->traces.current();
    if (ref && lap && !c->ghost) {
      if (auto d = c->traces.distanceNow(t, at, s.speed_mm_s, s.offset_mm, s.reverse)) {
        j["delta"] = round3((at - lap->start) - ref->lap.timeAt(*d));
        j["deltaTo"] = ref->label;
      }
    }
  }
  return j;
}

void Feed::setPersonalBest(laps::LapTrace lap, std::string label) {
  personal_ = Reference{std::move(lap), std::move(label)};
  ++changes_;
}

const Feed::Reference* Feed::reference() const {
  if (ghost_) return &*ghost_;
  if (best_ && personal_) return personal_->lap.time < best_->lap.time ? &*personal_ : &*best_;
  return best_ ? &*best_ : personal_ ? &*personal_ : nullptr;
}

// The reference lap as a ghost the page draws: it starts at the line when the leading car (the
// most laps; of two, the one that crossed first) last crossed it, and waits there when its lap
// is done before the car's. None while a simulated ghost races (it is drawn already), before
// the leader's first crossing, or with no reference or no track.
const Feed::Car* Feed::ghostLeader(int& number) const {
  if (!reference() || !track_ || !lapMap_ || lapMap_->n == 0) return nullptr;
  const Car* leader = nullptr;
  for (const auto& [n, c] : cars_) {
    if (c->ghost) return nullptr;
    const laps::LapTrace* lap = c->traces.current();
    if (!lap) continue;
    const laps::LapTrace* best = leader ? leader->traces.current() : nullptr;
    if (!leader || c->tracker.laps() > leader->tracker.laps() ||
        (c->tracker.laps() == leader->tracker.laps() && lap->start < best->start)) {
      leader = c.get();
      number = n;
    }
  }
  return leader;
}

std::uint64_t Feed::changes() const {
  // The view's ghost drives with the clock, not with the cars' frames: while it drives, a new
  // count every 50 ms, so that browsers get its place even when no car moves
  int number = 0;
  const Car* leader = ghostLeader(number);
  if (!leader) return changes_;
  const double t = now() - leader->traces.current()->start;
  if (t < 0 || t > reference()->lap.time) return changes_;
  return changes_ + 1 + static_cast<std::uint64_t>(now() * 20);
}

nlohmann::json Feed::viewGhostJson() const {
  int leaderNumber = 0;
  const Car* leader = ghostLeader(leaderNumber);
  if (!leader) return nullptr;
  const laps::LapTrace& lap = reference()->lap;
  const Reference* ref = reference();
  const double at = now();
  const double t = std::clamp(at - leader->traces.current()->start, 0.0, lap.time);
  const double d = std::clamp(lap.distanceAt(t), 0.0, lapMap_->lap);
  std::size_t k = 0;
  while (k + 1 < lapMap_->n && d >= lapMap_->start[k + 1]) ++k;
  const double fraction = lapMap_->length[k] > 0
                              ? std::clamp((d - lapMap_->start[k]) / lapMap_->length[k], 0.0, 1.0)
                              : 0.0;
  const double offset =  // (on the road: a kept lap's offsets are any numbers)
      std::clamp(lap.offsetOn(k, *lapMap_), anki::limits::kOffsetMin, anki::limits::kOffsetMax);
  const std::size_t index = lapMap_->trackIndex(k);
  // its speed along the lap here (the page moves it on between updates, as it moves the cars)
  constexpr double kAround = 0.05;
  const double speed = t >= lap.time
                           ? 0.0
                           : (lap.distanceAt(std::min(lap.time, t + kAround)) -
                              lap.distanceAt(std::max(0.0, t - kAround))) /
                                 (std::min(lap.time, t + kAround) - std::max(0.0, t - kAround));
  Pose p = pointOnTrack(*track_, index, fraction, offset);
  return {{"label", ref->label},
          {"follows", leaderNumber},
          {"t", round3(t)},
          {"pieceIndex", index},
          {"fraction", round3(fraction)},
          {"offset", round3(offset)},
          {"speed", round3(speed)},
          {"x", round3(p.x)},
          {"y", round3(p.y)},
          {"heading", round3(p.heading)},
          {"at", round3(at)}};
}

nlohmann::json Feed::carsJson(bool history) const {
  nlohmann::json cars = nlohmann::json::array();
  for (const AnkiCar* car : fleet_.cars()) {
    nlohmann::json j = carJson(*car, history ? kLapsInState : kLapsInUpdate);
    if (history) {
      nlohmann::json h = nlohmann::json::array();
      if (auto it = cars_.find(car->identity().number); it != cars_.end())
        for (const auto& [t, v] : it->second->speeds) h.push_back({round3(t), v});
      j["speedHistory"] = std::move(h);
    }
    cars.push_back(std::move(j));
  }
  return cars;
}

// The seats as every page sees them: who holds which car, not who the holder is (a phone's
// connection id stays the server's).
nlohmann::json Feed::seatsJson() const {
  nlohmann::json seats = nlohmann::json::array();
  if (!seats_) return seats;
  for (const drive::Seat& s : seats_->all()) {
    const AnkiCar* car = fleet_.find(s.number);
    seats.push_back(
        {{"number", s.number},
         {"car", car ? nlohmann::json(car->identity().name) : nlohmann::json(nullptr)},
         {"held", s.held()},
         {"live", s.live},
         {"holder", s.held() ? nlohmann::json(drive::holderName(s.kind)) : nlohmann::json(nullptr)},
         {"player", s.held() ? nlohmann::json(s.player) : nlohmann::json(nullptr)},
         {"throttle", round3(s.throttle)}});
  }
  return seats;
}

nlohmann::json Feed::eventsJson(std::uint64_t from) const {
  nlohmann::json events = nlohmann::json::array();
  for (const Event& e : events_)
    if (e.seq >= from)
      events.push_back({{"seq", e.seq}, {"t", round3(e.t)}, {"level", e.level}, {"text", e.text}});
  return events;
}

nlohmann::json Feed::state() const {
  nlohmann::json events = eventsJson(0);
  return {{"type", "state"},
          {"version", 1},
          {"source", source_},
          {"time", round3(now())},
          {"track", track_ ? trackJson(*track_, trackSource_) : nlohmann::json(nullptr)},
          {"race", race_.is_null() ? nlohmann::json(nullptr) : race_},
          {"replay", replay_.is_null() ? nlohmann::json(nullptr) : replay_},
          {"cars", carsJson(true)},
          {"seats", seatsJson()},
          {"viewGhost", viewGhostJson()},
          {"events", std::move(events)}};
}

nlohmann::json Feed::update(std::uint64_t& cursor, std::uint64_t& trackSeen) const {
  return nlohmann::json::parse(updateText(cursor, trackSeen));  // the one way an update is made
}

std::string Feed::updateText(std::uint64_t& cursor, std::uint64_t& trackSeen) const {
  constexpr auto kReplace = nlohmann::json::error_handler_t::replace;
  if (sharedAt_ != changes_) {
    // the race's text as setRace dumped it: a script's table (up to pitwall.view.race's 8 MiB)
    // is not copied and dumped again for every move of a car
    shared_ =
        R"("cars":)" + carsJson(false).dump(-1, ' ', false, kReplace) + R"(,"race":)" + raceText_ +
        R"(,"replay":)" +
        (replay_.is_null() ? nlohmann::json(nullptr) : replay_).dump(-1, ' ', false, kReplace) +
        R"(,"seats":)" + seatsJson().dump(-1, ' ', false, kReplace);
    sharedAt_ = changes_;
  }
  // (the view's ghost moves with the clock, not with the cars' frames: made for every update)
  std::string text = R"({"type":"update","time":)" + nlohmann::json(round3(now())).dump() + "," +
                     shared_ + R"(,"viewGhost":)" + viewGhostJson().dump(-1, ' ', false, kReplace) +
                     R"(,"events":)" + eventsJson(cursor).dump(-1, ' ', false, kReplace);
  cursor = nextEvent_;
  if (trackSeen != trackVersion_) {
    text += R"(,"track":)" + (track_ ? trackJson(*track_, trackSource_) : nlohmann::json(nullptr))
                                 .dump(-1, ' ', false, kReplace);
    trackSeen = trackVersion_;
  }
  return text + "}";
}

}  // namespace pitwall::view
