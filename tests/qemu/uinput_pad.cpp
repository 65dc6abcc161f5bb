// A virtual gamepad made through the kernel's uinput (libevdev's uinput helpers), for
// tests/qemu/gamepad_guest.sh: the guest's evdev shows it as /dev/input/eventN, exactly as it
// shows a pad plugged in by USB. It reads commands on stdin, one a line:
//   axis CODE VALUE   an EV_ABS event and SYN_REPORT (CODE 5 = ABS_RZ, the right trigger)
//   key CODE VALUE    an EV_KEY event and SYN_REPORT (310 BTN_TL, 311 BTN_TR, 304 BTN_SOUTH)
//   unplug            destroys the device (as pulling its cable does), then exits
// and prints `device /dev/input/eventN` once the device is there.
//
//   uinput_pad [NAME [RZ]]    (exit 0; 1 when uinput refuses, saying why)
//
// RZ: where ABS_RZ is when the device appears (default 0, a trigger at rest); 128 makes it a
// hid-generic pad whose ABS_RZ is a right stick resting mid-range.
#include <fcntl.h>
#include <libevdev/libevdev-uinput.h>
#include <libevdev/libevdev.h>
#include <linux/input-event-codes.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
  const char* name = argc > 1 ? argv[1] : "pitwall test pad";
  const int rz = argc > 2 ? std::atoi(argv[2]) : 0;
  libevdev* dev = libevdev_new();
  libevdev_set_name(dev, name);
  libevdev_set_id_bustype(dev, BUS_USB);
  libevdev_set_id_vendor(dev, 0x045e);  // shaped like an Xbox 360 pad (xpad's ranges)
  libevdev_set_id_product(dev, 0x028e);
  for (unsigned code : {BTN_SOUTH, BTN_EAST, BTN_NORTH, BTN_WEST, BTN_TL, BTN_TR, BTN_TR2,
                        BTN_SELECT, BTN_START, BTN_MODE, BTN_THUMBL, BTN_THUMBR})
    libevdev_enable_event_code(dev, EV_KEY, code, nullptr);
  input_absinfo stick{0, -32768, 32767, 16, 128, 0};
  input_absinfo trigger{0, 0, 255, 0, 0, 0};
  input_absinfo hat{0, -1, 1, 0, 0, 0};
  for (unsigned code : {ABS_X, ABS_Y, ABS_RX, ABS_RY})
    libevdev_enable_event_code(dev, EV_ABS, code, &stick);
  libevdev_enable_event_code(dev, EV_ABS, ABS_Z, &trigger);
  input_absinfo rightTrigger = trigger;
  rightTrigger.value = rz;
  libevdev_enable_event_code(dev, EV_ABS, ABS_RZ, &rightTrigger);
  for (unsigned code : {ABS_HAT0X, ABS_HAT0Y}) libevdev_enable_event_code(dev, EV_ABS, code, &hat);

  libevdev_uinput* pad = nullptr;
  int rc = libevdev_uinput_create_from_device(dev, LIBEVDEV_UINPUT_OPEN_MANAGED, &pad);
  if (rc < 0) {
    std::fprintf(stderr, "uinput_pad: cannot make a device through /dev/uinput: %s\n",
                 std::strerror(-rc));
    return 1;
  }
  const char* node = libevdev_uinput_get_devnode(pad);
  std::printf("device %s\n", node ? node : "?");
  std::fflush(stdout);

  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream words(line);
    std::string what;
    unsigned code = 0;
    int value = 0;
    words >> what;
    if (what == "unplug") break;
    if (!(words >> code >> value) || (what != "axis" && what != "key")) {
      std::fprintf(stderr, "uinput_pad: cannot read '%s': give axis|key CODE VALUE, or unplug\n",
                   line.c_str());
      continue;
    }
    libevdev_uinput_write_event(pad, what == "axis" ? EV_ABS : EV_KEY, code, value);
    libevdev_uinput_write_event(pad, EV_SYN, SYN_REPORT, 0);
  }
  libevdev_uinput_destroy(pad);
  libevdev_free(dev);
  std::printf("unplugged\n");
  return 0;
}
