#include "engine/drive/gamepad_mapping.hpp"

#include <linux/input-event-codes.h>

#include <algorithm>
#include <cmath>

namespace pitwall::drive {

namespace {
// A trigger at rest sits at its minimum, give or take a little wear: 2 % of its travel reads 0
// when the driver gives no `flat` of its own.
constexpr double kTriggerRest = 0.02;
// A stick at rest wanders around its centre: 15 % of its half travel reads 0 (more when the
// driver's `flat` says so), so a stick let go never creeps a car forward.
constexpr double kStickRest = 0.15;

double quantized(double level) {
  return std::clamp(std::round(level * 100.0) / 100.0, 0.0, 1.0);
}
}  // namespace

bool isGamepad(const DeviceCaps& caps) {
  return caps.keys.count(BTN_GAMEPAD) > 0 || caps.keys.count(BTN_JOYSTICK) > 0;
}

GamepadMapping::GamepadMapping(const DeviceCaps& caps) {
  auto has = [&caps](int code) {
    auto it = caps.axes.find(code);
    return it != caps.axes.end() && it->second.maximum > it->second.minimum;
  };
  // A pad with its right stick on ABS_RX/ABS_RY, as the gamepad spec has it, has its triggers
  // on the Z axes: one resting at its minimum when opened is the throttle at once. Without them
  // ABS_RZ may well be the right stick (hid-generic pads), and the value read at open proves
  // nothing — the kernel holds 0 until the pad's first report — so it is the throttle only once
  // an event has brought it to rest at its minimum. (ABS_GAS and ABS_HAT2X come from drivers
  // that follow the spec: at rest when opened is enough.)
  const bool rightStick = has(ABS_RX) && has(ABS_RY);
  for (int code : {ABS_RZ, ABS_GAS, ABS_HAT2X}) {
    if (!has(code)) continue;
    auto it = caps.axes.find(code);
    trigger_ = code;
    triggerInfo_ = it->second;
    triggerValue_ = it->second.value;
    armed_ = (code != ABS_RZ || rightStick) && atRest(triggerInfo_, triggerValue_);
    source_ = ThrottleSource::Trigger;
    break;
  }
  if (auto it = caps.axes.find(ABS_Y); it != caps.axes.end()) {
    hasStick_ = it->second.maximum > it->second.minimum;
    stickInfo_ = it->second;
    stickValue_ = it->second.value;
  }
}

double GamepadMapping::triggerLevel(const AxisInfo& info, int value) {
  if (info.maximum <= info.minimum) return 0;
  const double span = static_cast<double>(info.maximum) - info.minimum;
  const double from = static_cast<double>(value) - info.minimum;
  const double rest = std::max(static_cast<double>(std::max(info.flat, 0)), kTriggerRest * span);
  if (from <= rest) return 0;
  return std::clamp(from / span, 0.0, 1.0);
}

bool GamepadMapping::atRest(const AxisInfo& info, int value) {
  return info.maximum > info.minimum && value >= info.minimum && triggerLevel(info, value) == 0;
}

double GamepadMapping::stickUp(const AxisInfo& info, int value) {
  if (info.maximum <= info.minimum) return 0;
  const double centre = (static_cast<double>(info.minimum) + info.maximum) / 2;
  const double half = centre - info.minimum;
  const double up = centre - value;  // up is towards the minimum (gamepad.rst: −Y is up)
  const double rest = std::max(static_cast<double>(std::max(info.flat, 0)), kStickRest * half);
  if (up <= rest || rest >= half) return 0;
  return std::clamp((up - rest) / (half - rest), 0.0, 1.0);
}

double GamepadMapping::wanted() const {
  if (brake_) return 0;
  if (armed_) return quantized(triggerLevel(triggerInfo_, triggerValue_));
  double level = digitalTrigger_ ? 1.0 : 0.0;
  if (hasStick_) level = std::max(level, stickUp(stickInfo_, stickValue_));
  return quantized(level);
}

std::optional<GamepadInput> GamepadMapping::event(int type, int code, int value, bool replay) {
  int lane = 0;
  if (type == EV_ABS) {
    if (code == trigger_) {
      triggerValue_ = value;
      if (!armed_) armed_ = atRest(triggerInfo_, value);
    } else if (code == ABS_Y && hasStick_)
      stickValue_ = value;
    else
      return std::nullopt;
  } else if (type == EV_KEY) {
    const bool pressed = value != 0;  // 1 press, 2 auto-repeat, 0 release
    switch (code) {
      case BTN_SOUTH:
        brake_ = pressed;
        break;
      case BTN_TR2:
        digitalTrigger_ = pressed;
        break;
      case BTN_TL:
      case BTN_TR:
        if (value != 1 || replay) return std::nullopt;
        lane = code == BTN_TL ? -1 : +1;
        break;
      default:
        return std::nullopt;
    }
  } else {
    return std::nullopt;
  }
  const double now = wanted();
  if (lane == 0 && now == sent_) return std::nullopt;
  sent_ = now;
  return GamepadInput{now, lane};
}

}  // namespace pitwall::drive
