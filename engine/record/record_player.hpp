#pragma once
// Plays a record back (pitwall replay, docs/view.md "Replays"): one car per recorded car number
// joins the fleet over a ReplayLink, and each recorded frame from a car (rx) reaches its AnkiCar
// at its recorded time, through the same codec and model as in the run, so every event and lap
// is computed again from the bytes. Frames to the cars (tx) are counted, not delivered: they are
// what the run sent.
//
// Time: position p of the record (seconds) is reached at loop time anchor + (p − anchorPos) /
// speed. On a virtual clock with speed 1 the loop's time is the record's time. On the real clock
// the playback can be paused, sped up and moved (seek): forward, the frames in between are
// delivered at once; backward, the cars and whoever follows them (onRewind) forget what they
// knew and the frames from the start are delivered again at once, up to the target.
#include <cstdint>
#include <functional>
#include <istream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/record/record_reader.hpp"
#include "engine/transport/replay_link.hpp"

namespace pitwall {

class RecordPlayer {
 public:
  // Adds the cars to `fleet` (in order of their recorded numbers, each connected at once), so
  // fleet car k is the k-th smallest number of the record: the same numbers as in the run when
  // the run's cars are all in it.
  // The frames are read from `in` as they are played (RecordStream), never all held: `summary`
  // (scanRecord of the same file) says which cars there are and how long it lasts. `in` must be
  // a file's (a seek backwards reads it again from its start) and outlive the player.
  RecordPlayer(Loop& loop, Fleet& fleet, std::istream& in, const RecordSummary& summary);
  ~RecordPlayer();
  RecordPlayer(const RecordPlayer&) = delete;
  RecordPlayer& operator=(const RecordPlayer&) = delete;

  void play();  // from position 0
  void pause(bool paused);
  // Clamped to 0..duration(). On the real clock the frames up to it are delivered in slices of
  // 20 ms of work with the loop turning between them (position() says how far it has come);
  // on a virtual clock at once.
  void seek(double seconds);
  void setSpeed(double speed);  // > 0

  // Seconds into the record: while a frame is delivered, its time.
  double position() const;
  double duration() const { return duration_; }
  double speed() const { return speed_; }
  bool paused() const { return paused_; }
  bool ended() const { return !next_ && !reading_; }

  // The recorded car numbers, ascending, and the fleet's car for one of them.
  const std::vector<int>& recordedCars() const { return numbers_; }
  AnkiCar* car(int recorded) const;
  std::uint64_t framesOut(int recorded) const;  // tx frames of that car in the record

  // Every frame has been delivered (again, after a seek backwards).
  std::function<void()> onEnd;
  // Before frames are delivered again from the start: forget what the frames taught.
  std::function<void()> onRewind;
  // A race line of the record at its time (JSON text of pitwall.view.race's table, or "null").
  std::function<void(const std::string& race)> onRace;
  // A frame the run sent to a car, decoded, at its time (the feed learns what the cars were
  // told: a car told to stop shows 0 once silent).
  std::function<void(AnkiCar& car, const anki::Message& message)> onSent;

 private:
  void deliverUpTo(double position);
  void catchUp();      // the next slice of a seek
  void deliverNext();  // delivers next_ and reads the one after it
  // Reads the next frame, at most kLinesPerRead lines at once: a long run of bad lines is read
  // on after the loop has turned (readOn), then the seek or the playback goes on.
  void readNext();
  void readOn();
  void schedule();
  void anchor(double position);
  double elapsedPosition() const;

  Loop& loop_;
  Fleet& fleet_;
  RecordStream stream_;
  double duration_ = 0;
  std::optional<RecordedFrame> next_;  // the next frame to play; nothing at the end
  double nextTime_ = 0;                // when it plays: its t, never before the one before
  std::vector<int> numbers_;
  struct Car {
    AnkiCar* car = nullptr;
    ReplayLink* link = nullptr;
    std::uint64_t framesOut = 0;
  };
  std::map<int, Car> cars_;
  Loop::TimerId timer_ = 0;
  bool playing_ = false, paused_ = false;
  double speed_ = 1;
  TimePoint anchorLoop_{0};
  double anchorPos_ = 0;
  std::optional<double> delivering_;  // the time of the frame being delivered
  double caught_ = 0;                 // the time of the last frame delivered
  std::optional<double> seekTarget_;  // a seek under way
  bool seekWasEnded_ = false;
  std::uint64_t seekGeneration_ = 0;  // a slice of an older seek does nothing
  bool reading_ = false;              // a read goes on after the loop has turned
  std::uint64_t readGeneration_ = 0;  // a read of the file before a rewind does nothing
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace pitwall
