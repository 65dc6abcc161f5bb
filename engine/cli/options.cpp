#include "engine/cli/options.hpp"

#include <cctype>
#include <list>

#include "engine/protocol/anki/firmware.hpp"

namespace pitwall::cli {

CLI::Option* addCarSource(CLI::App* cmd, CarSource& source, const char* when) {
  cmd->add_option("--seed", source.seed, "Seed of the simulator's and the script's randomness");
  auto* cars = cmd->add_option("--cars", source.cars,
                               "Number of simulated cars on the grid (default 4, at most 1000)")
                   ->check(CLI::Range(0, 1000));
  cmd->add_option("--track", source.track,
                  "Track layout: a name (oval, …) or a layout file; with --ble, the layout the "
                  "cars are on (its custom pieces' shapes, docs/tracks.md)")
      ->each([&source](const std::string&) { source.trackGiven = true; });
  auto* ble = cmd->add_flag("--ble", source.ble,
                            "Drive real cars over Bluetooth LE (BlueZ) instead of the simulator");
  ble->excludes(cars);  // real cars are the cars there are
  cmd->add_option("--sensor", source.sensor,
                  "What the simulated cars' sensors report: real (fitted to real cars: position "
                  "updates thin out with speed; the default), ideal (every code) or transitions "
                  "(no position update at all: the worst case)")
      ->check(CLI::IsMember({"real", "ideal", "transitions"}))
      ->excludes(ble);
  addFirmware(cmd, source.firmware, "the simulated cars")->excludes(ble);
  cmd->add_option("--car", source.carAddresses, "With --ble: only this car (repeatable)")
      ->needs(ble);
  cmd->add_option("--adapter", source.adapters,
                  "With --ble: use this controller, hci0, … (repeatable; default: all)")
      ->needs(ble);
  cmd->add_option("--cars-per-adapter", source.carsPerAdapter,
                  "With --ble: cars one controller is given at most (default 6; a car that does "
                  "not fit is left out with a sentence: add an --adapter)")
      ->check(CLI::Range(1, 64))
      ->needs(ble);
  cmd->add_option("--scan-timeout", source.scanTimeout,
                  std::string("With --ble: seconds to look for cars ") + when + " (default 5)")
      ->check(CLI::PositiveNumber)
      ->needs(ble);
  cmd->add_option("--budget", source.budget,
                  "Seconds of CPU time a callback may use before it is interrupted (default 0.1; "
                  "0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--lua-memory", source.luaMemory,
                  "MB of memory the script's Lua world may hold (default 512; 0: no limit)")
      ->check(CLI::Range(0, 1 << 20));
  cmd->add_option("--handler-errors", source.handlerErrors,
                  "Stop a car whose event handler fails this many times within "
                  "--handler-errors-window (default 5; 0: never, the car drives on)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--handler-errors-window", source.handlerErrorsWindow,
                  "Seconds in which --handler-errors failures of one handler stop its car "
                  "(default 10)")
      ->check(CLI::PositiveNumber);
  return ble;
}

CLI::Option* addFirmware(CLI::App* cmd, std::uint16_t& firmware, const char* whose) {
  return cmd
      ->add_option_function<std::string>(
          "--firmware",
          [&firmware](const std::string& text) {
            auto version = anki::parseFirmware(text);
            if (!version) throw CLI::ValidationError("--firmware", version.error());
            firmware = *version;
          },
          std::string("The firmware version ") + whose +
              " answer, in hex: 0x2b70 (the default) or one before 0x2b6e, e.g. 0x266e, whose "
              "frames have the older layouts (docs/simulator.md \"Firmware families\")")
      ->type_name("VERSION");
}

CLI::Option* addMqtt(CLI::App* cmd, MqttSettings& mqtt, double& timeout, const char* what) {
  auto* url = cmd->add_option(
      "--mqtt", mqtt.url,
      std::string("MQTT broker, mqtt://HOST[:PORT] or mqtts://HOST[:PORT]: ") + what);
  cmd->add_option("--mqtt-user", mqtt.user, "Username for the broker")->needs(url);
  cmd->add_option("--mqtt-password-file", mqtt.passwordFile,
                  "File whose first line is the password (default: $PITWALL_MQTT_PASSWORD)")
      ->needs(url);
  cmd->add_option("--mqtt-ca", mqtt.caFile,
                  "With mqtts://: the CA certificate (PEM) that signed the broker's")
      ->needs(url);
  cmd->add_option("--mqtt-client-id", mqtt.clientId, "MQTT client id (default: a random one)")
      ->needs(url);
  cmd->add_option("--mqtt-max-payload", mqtt.maxPayload,
                  "Refuse a payload from the broker larger than this many bytes, unread "
                  "(default 65536)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{256} * 1024 * 1024))
      ->needs(url);
  cmd->add_option("--mqtt-timeout", timeout,
                  "Seconds to wait for the broker (and --remote-cars) at start (default 5)")
      ->check(CLI::PositiveNumber)
      ->needs(url);
  return url;
}

CLI::Option* addRemoteCars(CLI::App* cmd, CarSource& source) {
  auto* url = addMqtt(cmd, source.mqtt, source.mqttTimeout,
                      "the cars that bridges on other hosts publish join as remote cars");
  cmd->add_option("--remote-cars", source.remoteCars,
                  "With --mqtt: wait until this many remote cars are online (default 0)")
      ->check(CLI::Range(0, 64))
      ->needs(url);
  return url;
}

namespace {
struct ViewOption {
  CLI::Option* option = nullptr;
  std::string value;
  std::optional<std::string>* target = nullptr;
  std::vector<std::string> hosts;  // --view-host
};
std::list<ViewOption> g_views;  // a list: the options keep pointers to the values
std::vector<std::string> g_viewHosts;

// A name a browser may reach the view by: a host name or an address, nothing else.
std::string checkViewHost(const std::string& name) {
  if (name.empty() || name.size() > 253)
    return "--view-host '" + name.substr(0, 60) +
           "': give the name a reverse proxy serves the view by, as in --view-host "
           "race.example.org";
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == ':' ||
          c == '[' || c == ']' || c == '_'))
      return "--view-host '" + name.substr(0, 60) + "': '" + std::string(1, c) +
             "' is not part of a host name: give a name or an address without a scheme, path or "
             "port, as in --view-host race.example.org";
  return {};
}
}  // namespace

CLI::Option* addView(CLI::App* cmd, std::optional<std::string>& target) {
  auto& v = g_views.emplace_back();
  v.target = &target;
  v.option = cmd->add_option("--view", v.value,
                             "Serve the race view in a browser on [HOST:]PORT (default "
                             "127.0.0.1:8080; PORT 0: any free port) — docs/view.md")
                 ->expected(0, 1);
  cmd->add_option("--view-host", v.hosts,
                  "With --view: another NAME browsers reach the view by (a reverse proxy's; "
                  "repeatable). Requests for other names are refused (DNS rebinding); with it, "
                  "driving needs the join code — docs/view.md")
      ->check(checkViewHost)
      ->take_all()
      ->needs(v.option);
  return v.option;
}

void addHumans(CLI::App* cmd, CarSource& source) {
  auto* humans = cmd->add_option("--humans", source.humans,
                                 "Open cars 1..N to human drivers: phones on --view's /drive page, "
                                 "--gamepads, --keyboard (docs/racing.md)")
                     ->check(CLI::Range(0, 64));
  cmd->add_flag("--gamepads", source.gamepads,
                "With --humans: every gamepad plugged in takes a free seat (docs/controllers.md)")
      ->needs(humans);
  cmd->add_flag("--keyboard", source.keyboard,
                "With --humans: this terminal's arrow keys drive the first free seat")
      ->needs(humans);
}

void takeViews() {
  for (auto& v : g_views)
    if (v.option->count() > 0) {
      *v.target = v.value;
      g_viewHosts = v.hosts;
    }
}

const std::vector<std::string>& viewHosts() {
  return g_viewHosts;
}

void addDriverLimits(CLI::App* cmd, DriverLimitOptions& limits, const std::string& each) {
  cmd->add_option("--driver-memory", limits.driverMemory,
                  "MB " + each + " may hold (default 64); past it the driver is out")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--driver-budget", limits.driverBudget,
                  "Seconds of CPU one call into " + each +
                      " may take (default 0.05); past it the driver is out")
      ->check(CLI::Range(0.001, 10.0));
}

}  // namespace pitwall::cli
