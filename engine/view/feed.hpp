#pragma once
// What the race view shows (docs/view.md): the track, every car where the controller believes
// it is, the race as the race library reports it, and an event log. The feed follows the fleet's
// frames (subscribed to Fleet::frames and connectionChanged, as the MQTT bridge is) and the
// engine's log; the server turns it into /api/state and /ws updates. It sends nothing to a car.
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/drive/seats.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/laps/trace.hpp"
#include "engine/laps/tracker.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::view {

// A car's link health as the view's state and the record carry it (docs/view.md, docs/cli.md
// "Record format"): {connects, drops, lastDrop, writeFailures, stalls, rssi}.
nlohmann::json linkJson(const AnkiCar& car);

class Feed {
 public:
  // `source`: what the cars are ("simulator", "ble", "mqtt", "replay"), shown by the page.
  Feed(Loop& loop, Fleet& fleet, std::string source);
  ~Feed();
  Feed(const Feed&) = delete;
  Feed& operator=(const Feed&) = delete;

  // The track drawn: a layout ("layout"), a map a scan learnt ("scan"); none clears it.
  void setTrack(std::optional<sim::Track> track, const std::string& source);
  const std::optional<sim::Track>& track() const { return track_; }
  bool trackSourceIsLayout() const { return track_ && trackSource_ == "layout"; }
  // The race as the race library reports it (pitwall.view.race): phase, title, rows, laps.
  // null: no race. Any JSON object is taken as it is.
  void setRace(nlohmann::json race);
  // Playback of a recording (pitwall replay): duration, position, speed, paused.
  void setReplay(nlohmann::json replay) {
    replay_ = std::move(replay);
    ++changes_;
  }
  // The seats of human drivers (--humans N), shown to every page and taken by the controller
  // page (/drive); nullptr: none (driving is off). The seats must outlive the feed or be set
  // to nullptr before they go.
  void setSeats(drive::Seats* seats);
  drive::Seats* seats() const { return seats_; }
  // One line of the event log: level "info", "warn" or "error".
  void event(const std::string& level, const std::string& text);
  // The engine's warnings and errors, and its reload lines, join the event log while `on`.
  void followLog(bool on);

  // The whole state: GET /api/state and a browser's first message on /ws.
  nlohmann::json state() const;
  // What changed for one browser: the cars and the race now, events after `cursor` (advanced),
  // the track only when it changed since `trackSeen` (updated).
  nlohmann::json update(std::uint64_t& cursor, std::uint64_t& trackSeen) const;
  // The same update as text, for the server: the cars, the race and the replay are serialised
  // once per change of the feed and shared by every browser; only the events and the track are
  // each browser's own.
  std::string updateText(std::uint64_t& cursor, std::uint64_t& trackSeen) const;
  // Counts every change of what an update carries but the time: a frame that moved a car, the
  // race, the replay, an event, the track; and, while the view's ghost drives, every 50 ms of
  // the clock. Equal counts: nothing to send.
  std::uint64_t changes() const;
  std::uint64_t eventCursor() const { return nextEvent_; }
  std::uint64_t trackVersion() const { return trackVersion_; }

  // A control message from a page ({"type":"control",…}): replays use it to pause, seek and set
  // the speed. Unset: controls are refused.
  std::function<void(const nlohmann::json& control)> onControl;

  // The time the feed stamps and shows, in seconds; unset: the loop's. A replay sets its
  // position in the record, so laps are timed in the record's time at any playback speed.
  void setClock(std::function<double()> seconds) { clock_ = std::move(seconds); }
  // Cars told to stop fall silent, so their last reported speed would stay on the page: a car
  // whose last command was speed 0 and that has reported no speed for half a second is shown
  // at 0 from then on, until it reports its speed again (the rule of AnkiCar::standing). Called
  // before updates are made; counts a change when a car comes to stand.
  void settle();
  // A command to a car the fleet did not send: a replay's recorded one (what the run sent).
  void sent(AnkiCar& car, const anki::Message& m);
  // Forgets every car's tracker and speed history (a replay moving backwards replays the frames
  // from the start); the track, the race, the events stay.
  void reset();

  // The tracker of car `number` (for replay summaries and tests); nullptr when unknown.
  const laps::CarTracker* tracker(int number) const;
  // The traces of car `number`'s last laps (kLapsKept at most), oldest first: for `pitwall
  // compare` and the view's lap comparison; nullptr when unknown. Empty with no track.
  const std::deque<laps::LapTrace>* laps(int number) const;
  static constexpr std::size_t kLapsKept = 200;
  // Every car the feed follows: its number and name, by number.
  std::vector<std::pair<int, std::string>> tracedCars() const;
  // A personal best the standings keep for this track (docs/view.md "Ghosts and deltas"): the
  // reference of the live deltas and the view's ghost until the session drives a faster lap. A
  // new track forgets it.
  void setPersonalBest(laps::LapTrace lap, std::string label);
  // The view's ghost ("viewGhost" of the state; null: none): the reference lap driven from the
  // leading car's last line crossing — drawn beside the cars when no simulated ghost races.
  nlohmann::json viewGhostJson() const;

 private:
  struct Car;
  Car& car(AnkiCar& car);
  void frame(AnkiCar& car, AnkiCar::Direction d, const anki::Message& m);
  nlohmann::json carJson(const AnkiCar& car, std::size_t laps) const;
  bool stands(const Car& c) const;
  nlohmann::json carsJson(bool history) const;
  nlohmann::json seatsJson() const;

  double now() const { return clock_ ? clock_() : loop_.seconds(); }

  Loop& loop_;
  Fleet& fleet_;
  std::function<double()> clock_;
  std::string source_;
  std::optional<sim::Track> track_;
  std::string trackSource_ = "none";
  std::uint64_t trackVersion_ = 0;
  nlohmann::json race_;
  std::string raceText_ = "null";  // race_ dumped (setRace)
  nlohmann::json replay_;
  struct Event {
    std::uint64_t seq;
    double t;
    std::string level, text;
  };
  std::deque<Event> events_;
  std::uint64_t nextEvent_ = 0;
  std::map<int, std::unique_ptr<Car>> cars_;
  struct Reference {
    laps::LapTrace lap;
    std::string label;
  };
  // the ghost's last lap; the session's best lap; the standings' personal best on this track
  std::optional<Reference> ghost_, best_, personal_;
  const Reference* reference() const;  // of the deltas: the ghost's lap, else the fastest
  // The car the view's ghost follows (its number in `number`); nullptr: no view's ghost now.
  const Car* ghostLeader(int& number) const;
  std::optional<laps::LapMap> lapMap_;  // of track_
  const AnkiCar* lastAnki_ = nullptr;   // the car of the last car() and its Car: one lookup fewer
  int lastNumber_ = 0;
  Car* lastCar_ = nullptr;
  Subscription framesSub_, connectionSub_;  // the fleet's events, while the feed lives
  drive::Seats* seats_ = nullptr;
  Subscription seatsSub_, askedSub_;  // the seats' changes, and their holders' asks
  std::uint64_t logTap_ = 0;
  std::uint64_t changes_ = 0;
  mutable std::string shared_;  // updateText's shared part, as of change sharedAt_
  mutable std::uint64_t sharedAt_ = ~std::uint64_t{0};
  nlohmann::json eventsJson(std::uint64_t from) const;
};

}  // namespace pitwall::view
