#pragma once
// What a gamepad's evdev events ask of a human seat (docs/controllers.md "Gamepads"): a throttle
// 0..1 and lane steps. Pure: no device, no I/O — engine/drive/gamepads.cpp feeds it the events
// libevdev reads, the unit tests feed it hostile ones.
//
// The mapping follows the Linux gamepad specification (kernel Documentation/input/gamepad.rst):
// - throttle: the right trigger, an analog axis — ABS_RZ (xpad, hid-playstation, hid-sony and
//   most HID pads report the right trigger there), else ABS_GAS (racing pads), else ABS_HAT2X
//   (gamepad.rst: "Lower trigger buttons are reported as BTN_TR2 or ABS_HAT2X (right/ZR)") —
//   normalized with its absinfo; a pad without one: the digital right trigger BTN_TR2 (full
//   while held), and the left stick pushed up (−ABS_Y, outside a deadzone) whichever is more;
// - a trigger axis counts only once it has been seen at rest, within its rest zone at its
//   minimum (when the device is opened, or later): on many hid-generic pads (Logitech F310 in
//   D mode, DragonRise) ABS_Z/ABS_RZ is the right stick, resting mid-range, and some wheels'
//   pedals rest at their maximum — read as a trigger, that is half or full throttle with no hand
//   on it. Until then the axis reads 0 and BTN_TR2 and the left stick drive as on a pad without
//   one;
// - lanes: BTN_TL (left shoulder) one lane left, BTN_TR (right shoulder) one lane right, on the
//   press (not on the kernel's auto-repeat, not on the release);
// - brake: BTN_SOUTH (A on Xbox pads, cross on PlayStation ones) held: throttle 0, whatever the
//   trigger says.
#include <cstdint>
#include <map>
#include <optional>
#include <set>

namespace pitwall::drive {

// An absolute axis' range as the kernel gives it (struct input_absinfo).
struct AxisInfo {
  int minimum = 0;
  int maximum = 0;
  int flat = 0;   // the driver's deadzone around the rest position, in axis units
  int value = 0;  // where it is now
};

// What a device offers: its EV_KEY codes and its EV_ABS axes.
struct DeviceCaps {
  std::set<int> keys;
  std::map<int, AxisInfo> axes;
};

// A gamepad has the gamepad buttons (BTN_GAMEPAD = BTN_SOUTH) or is a joystick (BTN_JOYSTICK):
// keyboards, mice, touchpads, power buttons and accelerometers are left alone.
bool isGamepad(const DeviceCaps& caps);

// Where the throttle comes from on a device, for its log line ("right trigger ABS_RZ").
enum class ThrottleSource { Trigger, StickAndButton };

struct GamepadInput {
  double throttle = 0;  // 0..1, a multiple of 0.01
  int laneStep = 0;     // −1, 0, +1
};

class GamepadMapping {
 public:
  explicit GamepadMapping(const DeviceCaps& caps);

  ThrottleSource source() const { return source_; }
  int triggerAxis() const { return trigger_; }  // the ABS code, or −1
  // The trigger axis has been seen at rest at its minimum and is the throttle; false before
  // (BTN_TR2 and the left stick drive meanwhile) and on a pad without one. ABS_RZ seen there at
  // open counts only on a pad with a right stick on ABS_RX/ABS_RY (the gamepad spec's layout);
  // on others an event must bring it there.
  bool triggerArmed() const { return armed_; }

  // One event (type, code, value as struct input_event has them). The input to send when the
  // throttle changed or a lane button was pressed; nothing otherwise. `replay`: an event of a
  // resync after SYN_DROPPED, which brings the state up to date but presses no lane button
  // (the press itself was lost; stepping a lane late would surprise the player).
  std::optional<GamepadInput> event(int type, int code, int value, bool replay = false);

  double throttle() const { return sent_; }

  // An axis value as 0..1 over its range (min→0, max→1), the driver's `flat` zone at the rest
  // end read as 0; a range with min ≥ max reads 0. Exposed for the tests.
  static double triggerLevel(const AxisInfo& info, int value);
  // How far a stick is pushed up (towards min): 0 at or below the centre plus deadzone, 1 at min.
  static double stickUp(const AxisInfo& info, int value);
  // A trigger at rest: within its rest zone at the minimum (triggerLevel 0, not below the range).
  static bool atRest(const AxisInfo& info, int value);

 private:
  double wanted() const;

  ThrottleSource source_ = ThrottleSource::StickAndButton;
  int trigger_ = -1;
  AxisInfo triggerInfo_;
  bool armed_ = false;
  bool hasStick_ = false;
  AxisInfo stickInfo_;
  int triggerValue_ = 0;
  int stickValue_ = 0;
  bool digitalTrigger_ = false;
  bool brake_ = false;
  double sent_ = 0;
};

}  // namespace pitwall::drive
