// A gamepad's events → what its seat is asked (engine/drive/gamepad_mapping.hpp): the Linux
// gamepad specification's trigger, stick and buttons, and input no driver should send.
#include <doctest/doctest.h>
#include <linux/input-event-codes.h>

#include <climits>
#include <random>

#include "engine/drive/gamepad_mapping.hpp"

using namespace pitwall::drive;

namespace {

// An Xbox-like pad as xpad reports it: triggers 0..1023 on ABS_Z/ABS_RZ, sticks ±32767.
DeviceCaps xboxPad() {
  DeviceCaps caps;
  caps.keys = {BTN_SOUTH, BTN_EAST, BTN_NORTH, BTN_WEST, BTN_TL, BTN_TR, BTN_START, BTN_SELECT};
  caps.axes[ABS_X] = {-32768, 32767, 128, 0};
  caps.axes[ABS_Y] = {-32768, 32767, 128, 0};
  caps.axes[ABS_RX] = {-32768, 32767, 128, 0};
  caps.axes[ABS_RY] = {-32768, 32767, 128, 0};
  caps.axes[ABS_Z] = {0, 1023, 0, 0};
  caps.axes[ABS_RZ] = {0, 1023, 0, 0};
  return caps;
}

// A pad with no analog trigger: a stick 0..255 (centre 127.5) and digital ZR.
DeviceCaps stickPad() {
  DeviceCaps caps;
  caps.keys = {BTN_SOUTH, BTN_TL, BTN_TR, BTN_TL2, BTN_TR2};
  caps.axes[ABS_X] = {0, 255, 15, 128};
  caps.axes[ABS_Y] = {0, 255, 15, 128};
  return caps;
}

// The throttle that `m.event(...)` asks for; the event must ask for one.
double throttleOf(GamepadMapping& m, int type, int code, int value, bool replay = false) {
  auto in = m.event(type, code, value, replay);
  REQUIRE(in);
  return in->throttle;
}

}  // namespace

TEST_CASE("gamepad: a device with gamepad or joystick buttons is a gamepad; a keyboard is not") {
  CHECK(isGamepad(xboxPad()));
  DeviceCaps joystick;
  joystick.keys = {BTN_TRIGGER, BTN_THUMB};  // BTN_JOYSTICK == BTN_TRIGGER
  CHECK(isGamepad(joystick));
  DeviceCaps keyboard;
  keyboard.keys = {KEY_A, KEY_UP, KEY_SPACE};
  CHECK_FALSE(isGamepad(keyboard));
  DeviceCaps mouse;
  mouse.keys = {BTN_LEFT, BTN_RIGHT};
  CHECK_FALSE(isGamepad(mouse));
  CHECK_FALSE(isGamepad(DeviceCaps{}));
}

TEST_CASE("gamepad: the right trigger is the throttle, normalized over its range") {
  GamepadMapping m(xboxPad());
  CHECK(m.source() == ThrottleSource::Trigger);
  CHECK(m.triggerAxis() == ABS_RZ);
  auto half = m.event(EV_ABS, ABS_RZ, 512);
  REQUIRE(half);
  CHECK(half->throttle == doctest::Approx(0.50));
  CHECK(half->laneStep == 0);
  CHECK(throttleOf(m, EV_ABS, ABS_RZ, 1023) == 1.0);
  CHECK(throttleOf(m, EV_ABS, ABS_RZ, 0) == 0.0);
  // the left trigger and the sticks do nothing while a right trigger is there
  CHECK_FALSE(m.event(EV_ABS, ABS_Z, 1023));
  CHECK_FALSE(m.event(EV_ABS, ABS_Y, -32768));
  CHECK_FALSE(m.event(EV_ABS, ABS_X, 32767));
}

TEST_CASE("gamepad: an input goes out only when the throttle changes by a hundredth or more") {
  GamepadMapping m(xboxPad());
  REQUIRE(m.event(EV_ABS, ABS_RZ, 512));
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 512));  // the same again
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 513));  // a jitter below 1 %
  CHECK(m.event(EV_ABS, ABS_RZ, 530));
  CHECK_FALSE(m.event(EV_SYN, SYN_REPORT, 0));
  CHECK_FALSE(m.event(EV_MSC, MSC_SCAN, 90001));
}

TEST_CASE("gamepad: a trigger resting near its minimum reads 0 (its flat zone, or 2 %)") {
  CHECK(GamepadMapping::triggerLevel({0, 1023, 0, 0}, 15) == 0.0);
  CHECK(GamepadMapping::triggerLevel({0, 1023, 100, 0}, 90) == 0.0);
  CHECK(GamepadMapping::triggerLevel({0, 1023, 100, 0}, 110) > 0.0);
  // a trigger whose range is not from 0: −100..100 (a HAT2X-style axis)
  CHECK(GamepadMapping::triggerLevel({-100, 100, 0, 0}, -100) == 0.0);
  CHECK(GamepadMapping::triggerLevel({-100, 100, 0, 0}, 0) == doctest::Approx(0.5));
  CHECK(GamepadMapping::triggerLevel({-100, 100, 0, 0}, 100) == 1.0);
}

TEST_CASE("gamepad: out-of-range axis values are clamped, never beyond 0..1") {
  GamepadMapping m(xboxPad());
  CHECK(throttleOf(m, EV_ABS, ABS_RZ, INT_MAX) == 1.0);
  CHECK(throttleOf(m, EV_ABS, ABS_RZ, INT_MIN) == 0.0);
  CHECK(GamepadMapping::stickUp({-32768, 32767, 0, 0}, INT_MIN) == 1.0);
  CHECK(GamepadMapping::stickUp({-32768, 32767, 0, 0}, INT_MAX) == 0.0);
  CHECK(GamepadMapping::triggerLevel({INT_MIN, INT_MAX, 0, 0}, INT_MAX) == 1.0);
  CHECK(GamepadMapping::triggerLevel({INT_MIN, INT_MAX, INT_MAX, 0}, -1) ==
        0.0);  // in its flat zone
  CHECK(GamepadMapping::stickUp({INT_MIN, INT_MAX, INT_MIN, 0}, INT_MIN) == 1.0);
}

TEST_CASE("gamepad: absinfo with min == max (or min > max) gives no throttle from that axis") {
  CHECK(GamepadMapping::triggerLevel({5, 5, 0, 5}, 5) == 0.0);
  CHECK(GamepadMapping::triggerLevel({10, -10, 0, 0}, 7) == 0.0);
  CHECK(GamepadMapping::stickUp({0, 0, 0, 0}, -1000) == 0.0);
  CHECK(GamepadMapping::stickUp({0, 255, 200, 128}, 0) == 0.0);  // a flat wider than the travel
  // A broken right trigger is passed over for the next axis the specification names.
  DeviceCaps caps = xboxPad();
  caps.axes[ABS_RZ] = {0, 0, 0, 0};
  caps.axes[ABS_GAS] = {0, 255, 0, 0};
  GamepadMapping m(caps);
  CHECK(m.triggerAxis() == ABS_GAS);
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 100));
  REQUIRE(m.event(EV_ABS, ABS_GAS, 255));
  CHECK(m.throttle() == 1.0);
  // …and with none at all, a stick with no range gives nothing either.
  DeviceCaps dead;
  dead.keys = {BTN_SOUTH};
  dead.axes[ABS_Y] = {3, 3, 0, 3};
  GamepadMapping d(dead);
  CHECK(d.source() == ThrottleSource::StickAndButton);
  CHECK_FALSE(d.event(EV_ABS, ABS_Y, -100000));
}

TEST_CASE("gamepad: ABS_HAT2X, the specification's analog ZR, is a trigger too") {
  DeviceCaps caps;
  caps.keys = {BTN_SOUTH};
  caps.axes[ABS_HAT2X] = {0, 255, 0, 0};
  GamepadMapping m(caps);
  CHECK(m.triggerAxis() == ABS_HAT2X);
  REQUIRE(m.event(EV_ABS, ABS_HAT2X, 255));
  CHECK(m.throttle() == 1.0);
}

// A hid-generic pad (Logitech F310 in D mode, DragonRise): ABS_Z/ABS_RZ is the right stick,
// resting mid-range; BTN_TR2 is the digital right trigger.
DeviceCaps stickOnRz() {
  DeviceCaps caps = stickPad();
  caps.axes[ABS_Z] = {0, 255, 15, 128};
  caps.axes[ABS_RZ] = {0, 255, 15, 128};
  return caps;
}

TEST_CASE(
    "gamepad: an ABS_RZ resting mid-range is no throttle; pressing and letting go of A sends "
    "none") {
  GamepadMapping m(stickOnRz());
  CHECK(m.triggerAxis() == ABS_RZ);
  CHECK_FALSE(m.triggerArmed());
  // A pressed and let go: the brake lets go to 0, not to the stick's half way
  auto brake = m.event(EV_KEY, BTN_SOUTH, 1);
  CHECK((!brake || brake->throttle == 0.0));
  auto letGo = m.event(EV_KEY, BTN_SOUTH, 0);
  CHECK((!letGo || letGo->throttle == 0.0));
  CHECK(m.throttle() == 0.0);
  // the right stick moved about, never to its minimum: still nothing
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 200));
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 255));
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 60));
  CHECK_FALSE(m.triggerArmed());
  // meanwhile BTN_TR2 and the left stick up drive, as on a pad without an analog trigger
  CHECK(throttleOf(m, EV_KEY, BTN_TR2, 1) == 1.0);
  CHECK(throttleOf(m, EV_KEY, BTN_TR2, 0) == 0.0);
  CHECK(throttleOf(m, EV_ABS, ABS_Y, 0) == 1.0);
  REQUIRE(m.event(EV_ABS, ABS_Y, 128));
  CHECK(m.throttle() == 0.0);
}

TEST_CASE("gamepad: a trigger not at rest when opened is the throttle once seen at its minimum") {
  DeviceCaps caps = stickPad();
  caps.axes[ABS_RZ] = {0, 255, 15, 255};  // a pedal pressed (or resting at max) when opened
  GamepadMapping m(caps);
  CHECK_FALSE(m.triggerArmed());
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 250));
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, INT_MIN));  // below the range is no rest either
  CHECK_FALSE(m.triggerArmed());
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 10));  // within its flat zone at the minimum: at rest
  CHECK(m.triggerArmed());
  CHECK(throttleOf(m, EV_ABS, ABS_RZ, 128) == doctest::Approx(0.50));
  // armed, the trigger alone is the throttle: the stick and BTN_TR2 no longer add to it
  CHECK_FALSE(m.event(EV_ABS, ABS_Y, 0));
  CHECK_FALSE(m.event(EV_KEY, BTN_TR2, 1));
  // an xpad trigger opened at 0 is armed from the start
  CHECK(GamepadMapping(xboxPad()).triggerArmed());
  CHECK(GamepadMapping::atRest({0, 1023, 0, 0}, 20));
  CHECK_FALSE(GamepadMapping::atRest({0, 1023, 0, 0}, 512));
  CHECK_FALSE(GamepadMapping::atRest({0, 0, 0, 0}, 0));
}

TEST_CASE("gamepad: without an analog trigger, the left stick up or the digital ZR drive") {
  GamepadMapping m(stickPad());
  CHECK(m.source() == ThrottleSource::StickAndButton);
  CHECK(m.triggerAxis() == -1);
  CHECK_FALSE(m.event(EV_ABS, ABS_Y, 120));  // near the centre: the deadzone
  CHECK_FALSE(m.event(EV_ABS, ABS_Y, 255));  // down is not reverse: 0
  CHECK(throttleOf(m, EV_ABS, ABS_Y, 0) == 1.0);
  const double partway = throttleOf(m, EV_ABS, ABS_Y, 64);
  CHECK(partway > 0.3);
  CHECK(partway < 0.7);
  REQUIRE(m.event(EV_ABS, ABS_Y, 128));
  CHECK(m.throttle() == 0.0);
  CHECK(throttleOf(m, EV_KEY, BTN_TR2, 1) == 1.0);
  CHECK(throttleOf(m, EV_KEY, BTN_TR2, 0) == 0.0);
}

TEST_CASE("gamepad: the shoulder buttons step a lane on the press, not on repeat or release") {
  GamepadMapping m(xboxPad());
  auto left = m.event(EV_KEY, BTN_TL, 1);
  REQUIRE(left);
  CHECK(left->laneStep == -1);
  CHECK_FALSE(m.event(EV_KEY, BTN_TL, 2));  // auto-repeat
  CHECK_FALSE(m.event(EV_KEY, BTN_TL, 0));  // release
  auto right = m.event(EV_KEY, BTN_TR, 1);
  REQUIRE(right);
  CHECK(right->laneStep == +1);
  CHECK(right->throttle == 0.0);
  // a press replayed by a resync after SYN_DROPPED steps no lane
  CHECK_FALSE(m.event(EV_KEY, BTN_TR, 1, /*replay=*/true));
}

TEST_CASE("gamepad: BTN_SOUTH held brakes to 0 whatever the trigger; let go, the trigger counts") {
  GamepadMapping m(xboxPad());
  REQUIRE(m.event(EV_ABS, ABS_RZ, 1023));
  CHECK(throttleOf(m, EV_KEY, BTN_SOUTH, 1) == 0.0);
  CHECK_FALSE(m.event(EV_ABS, ABS_RZ, 800));  // still braking
  CHECK(throttleOf(m, EV_KEY, BTN_SOUTH, 0) == doctest::Approx(0.78));
}

TEST_CASE("gamepad: replayed axis events after SYN_DROPPED bring the throttle up to date") {
  GamepadMapping m(xboxPad());
  CHECK(throttleOf(m, EV_ABS, ABS_RZ, 1023, /*replay=*/true) == 1.0);
}

TEST_CASE("gamepad: random events never give a throttle outside 0..1 or a lane step beyond 1") {
  std::mt19937 rng(22);
  std::uniform_int_distribution<int> type(0, EV_MAX);
  std::uniform_int_distribution<int> code(0, KEY_MAX);
  std::uniform_int_distribution<int> value(INT_MIN, INT_MAX);
  std::uniform_int_distribution<int> small(-2, 3);
  for (auto caps : {xboxPad(), stickPad(), DeviceCaps{}}) {
    GamepadMapping m(caps);
    for (int i = 0; i < 20000; ++i) {
      const int t = i % 3 == 0 ? EV_KEY : i % 3 == 1 ? EV_ABS : type(rng);
      const int c = i % 5 == 0 ? (t == EV_ABS ? ABS_RZ : BTN_TL) : code(rng) % (ABS_MAX + 1);
      const int v = i % 2 ? small(rng) : value(rng);
      auto out = m.event(t, c, v, i % 7 == 0);
      if (!out) continue;
      CHECK(out->throttle >= 0.0);
      CHECK(out->throttle <= 1.0);
      CHECK(out->laneStep >= -1);
      CHECK(out->laneStep <= 1);
    }
  }
}

TEST_CASE(
    "gamepad: without a right stick on RX/RY, ABS_RZ at 0 when opened is not yet the throttle") {
  // a hid-generic pad (DragonRise, F310 in D mode): X/Y the left stick, Z/RZ the right one; the
  // kernel holds 0 for every axis until the pad's first report, so 0 at open proves nothing
  DeviceCaps caps;
  caps.keys = {BTN_SOUTH, BTN_TL, BTN_TR, BTN_TR2, BTN_JOYSTICK};
  caps.axes[ABS_X] = {0, 255, 15, 0};
  caps.axes[ABS_Y] = {0, 255, 15, 0};
  caps.axes[ABS_Z] = {0, 255, 15, 0};
  caps.axes[ABS_RZ] = {0, 255, 15, 0};
  GamepadMapping m(caps);
  CHECK_FALSE(m.triggerArmed());
  // the first report: the right stick at rest, mid-range; the left stick at rest too
  m.event(EV_ABS, ABS_Y, 128);
  auto in = m.event(EV_ABS, ABS_RZ, 128);
  CHECK((!in || in->throttle == 0));
  CHECK(m.throttle() == 0);
  CHECK_FALSE(m.triggerArmed());
  // pressed to its minimum by an event: from then on it is taken as the throttle (documented)
  m.event(EV_ABS, ABS_RZ, 0);
  CHECK(m.triggerArmed());
}
