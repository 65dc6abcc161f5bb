#pragma once
// The robot side of the MindRoad protocol, simulated (../shared/protocols/mindroad.md): what a
// robot car does with each instruction, a body that drives by the steering values, and the
// watchdog. No I/O: MindroadRobotServer (mindroad_robot_server.hpp) feeds it bytes from the
// network and sends back what it answers.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/protocol/mindroad/codec.hpp"

namespace pitwall::sim {

struct MindroadRobotOptions {
  double watchdog = 0.5;    // s without an instruction before the robot stops (mindroad.md)
  double maxSpeed = 0.5;    // m/s at steering x = ±127/−128
  double maxTurnRate = 90;  // °/s at steering y = ±127/−128
  int ignoreContacts = 0;   // tests: the first N contact instructions get no answer
};

struct MindroadRobotState {
  bool contact = false;    // a contact was answered and no watchdog stop came since
  std::int8_t steerX = 0;  // the steering being obeyed (0, 0 when stopped)
  std::int8_t steerY = 0;
  double x = 0, y = 0;          // m; the body starts at the origin facing +x
  double heading = 0;           // degrees, counter-clockwise from +x; y > 0 turns right (clockwise)
  std::string mode = "manual";  // the last button read as an id (table 2)
  int sensitivity = 0;          // colour sensitivity, moved by the sensitivity buttons
  std::uint8_t buttons = 0;     // the last buttons byte, raw
  mindroad::Picture picture = mindroad::Picture::Rgb;
  int clickX = 0, clickY = 0;  // the last click (0 before any)
  std::uint64_t instructions = 0, malformed = 0, contacts = 0, ignored = 0;
  std::string lastStop;  // why it last stopped: "stop", "watchdog", "malformed: …", …
  bool shutdown = false;
  bool moving() const { return steerX != 0 || steerY != 0; }  // turning in place counts
};

class MindroadRobot {
 public:
  explicit MindroadRobot(MindroadRobotOptions options = {}) : options_(options) {}

  // One instruction (or decode error) received at time `now` (s). Returns the bytes to answer
  // (only K for contact). Calls onChange with a short event name when the state changed.
  std::vector<std::uint8_t> receive(const Result<mindroad::Instruction, mindroad::DecodeError>& in,
                                    double now);
  // Moves the body to `now` and applies the watchdog.
  void advance(double now);

  const MindroadRobotState& state() const { return state_; }
  const MindroadRobotOptions& options() const { return options_; }
  // event: "contact", "steer", "stop", "watchdog", "malformed", "click", "buttons",
  // "picture-mode", "ignored", "shutdown"; detail: one sentence for the log.
  std::function<void(const std::string& event, const std::string& detail)> onChange;

 private:
  void stop(const std::string& event, const std::string& why);
  void changed(const std::string& event, const std::string& detail);

  MindroadRobotOptions options_;
  MindroadRobotState state_;
  double lastInstruction_ = 0;
  double lastAdvance_ = 0;
  int contactsIgnored_ = 0;
};

}  // namespace pitwall::sim
