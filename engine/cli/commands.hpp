#pragma once
// The `pitwall` subcommands (docs/cli.md). Each returns the process exit status.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/print/commands.hpp"
#include "engine/protocol/anki/firmware.hpp"

namespace pitwall::cli {

// How to reach an MQTT broker (docs/mqtt.md): --mqtt URL and its companions.
struct MqttSettings {
  std::string url;           // mqtt://HOST[:PORT] or mqtts://HOST[:PORT]; empty: no broker
  std::string user;          // --mqtt-user
  std::string passwordFile;  // --mqtt-password-file; else $PITWALL_MQTT_PASSWORD when set
  std::string caFile;        // --mqtt-ca: the CA of the broker's certificate (mqtts://)
  std::string clientId;      // --mqtt-client-id; empty: a random one
  // --mqtt-max-payload: a larger payload from the broker is refused unread (docs/mqtt.md
  // "Hostile input"); topics::kDefaultMaxPayload
  std::size_t maxPayload = 64 * 1024;
};

// --driver-memory MB and --driver-budget S: each driver world's limits (docs/drivers.md), for run,
// league and try (addDriverLimits).
struct DriverLimitOptions {
  int driverMemory = 64;
  double driverBudget = 0.05;
};

// Where the cars of a run or a REPL come from: the simulator's starting grid, or real cars over
// Bluetooth LE through BlueZ (docs/bluetooth.md).
struct CarSource {
  std::uint64_t seed = 1;  // the simulator's noise and the script's math.random
  int cars = 4;            // simulated cars on the grid
  std::string track = "oval";
  std::string sensor = "real";  // --sensor real|ideal: the simulated cars' (docs/simulator.md)
  std::uint16_t firmware = anki::kFirmwareDefault;  // --firmware: the simulated cars' version
  bool trackGiven = false;  // --track was on the command line (else: an oval that holds `cars`)
  bool ble = false;
  std::vector<std::string> carAddresses;  // --car ADDR (repeatable): only these; empty: all found
  std::vector<std::string> adapters;      // --adapter hciN (repeatable); empty: every adapter
  double scanTimeout = 5;                 // seconds to look for cars before the script starts
  int carsPerAdapter = 6;  // --cars-per-adapter: cars one Bluetooth controller is given at most
  double budget = 0.1;     // --budget SECONDS a callback may run before it is interrupted; 0: off
  int luaMemory = 512;     // --lua-memory MB a script's Lua world may hold; 0: no limit
  // --handler-errors N, --handler-errors-window SECONDS: a car whose handler fails N times within
  // the window is stopped (bindings/car_binding.hpp); 0: never
  int handlerErrors = 5;
  double handlerErrorsWindow = 10;
  // --mqtt: the cars bridged by other hosts join as remote cars (docs/mqtt.md)
  MqttSettings mqtt;
  int remoteCars = 0;  // --remote-cars N: wait (up to --mqtt-timeout) until N are online
  double mqttTimeout = 5;
  // --view [[HOST:]PORT]: serve the race view (docs/view.md); "" the default port; none: off
  std::optional<std::string> view;
  // Human drivers (docs/racing.md "Human drivers"): --humans N opens cars 1..N to people, who
  // hold them from a phone (--view's /drive page), a gamepad (--gamepads) or this terminal's
  // keyboard (--keyboard).
  int humans = 0;
  bool gamepads = false;
  bool keyboard = false;
  // --ghost FILE[:CAR[:LAP]] | best[:NAME] (run): a ghost of that lap joins after the cars and
  // drives from the race's green light (docs/racing.md "Racing a ghost"); empty: none
  std::string ghost;
};

struct RunOptions : CarSource {
  std::string script;
  bool fast = false;
  std::optional<double> duration;  // seconds of engine time
  std::string record;              // --record FILE, empty: none
  std::string results;             // --results FILE (.json or .csv), empty: none
  bool repl = false;               // --repl: open the REPL in the script's Lua world
  bool watch = false;              // --watch: reload the script when one of its files is saved
  std::string history;             // --history FILE for the REPL; empty: the default
  // --fast-cap S: with --fast and no --duration, the simulated seconds after which a script that
  // has not ended the run is stopped and the run ends with kExitCapped; none: the default cap
  std::optional<double> fastCap;
  // --driver CAR=FILE (repeatable): the race's driver of car number CAR is FILE, in a Lua world of
  // its own, with the limits of `limits` (docs/drivers.md).
  std::vector<std::string> drivers;
  DriverLimitOptions limits;
  // --db FILE: the standings database its races are kept in (default: standings::defaultPath());
  // --no-db: none (docs/league.md "Standings")
  std::string db;
  bool noDb = false;
  // --league-final DB[:EVENT]: the top drivers of a league kept in DB race a final, the script
  // optional (docs/league.md "The final"); --final-cars K of them (default: as many as the cars)
  std::string leagueFinal;
  int finalCars = 0;
  // --code FOLDER: the view's code page (docs/classroom.md): a desk for each car, its driver file
  // in FOLDER/car-N/driver.lua, students editing it in the browser; the script defaults to the
  // shipped examples/classroom.lua
  std::string code;
};
int run(const RunOptions& options);
// The exit status of a --fast run that its safety cap ended (docs/cli.md).
constexpr int kExitCapped = 124;  // as timeout(1) does

// pitwall repl: a Lua prompt with the cars bound, on the simulator (real time) or --ble.
struct ReplOptions : CarSource {
  std::string history;  // empty: the default history file (docs/repl.md)
};
int repl(const ReplOptions& options);

struct TestOptions {
  std::vector<std::string> paths;
  std::string seed = "1";  // N, or "random": a seed of its own for each scenario
  double timeout = 600;    // seconds of virtual time per scenario
  double budget = 0.1;     // seconds of CPU time a callback may use before it is interrupted
  int luaMemory = 512;     // MB a scenario's Lua world may hold; 0: no limit
  std::vector<std::string> filters;  // --filter: a scenario runs when one matches
  bool list = false;
  int jobs = 0;       // 0: the number of cores
  std::string junit;  // --junit FILE
  bool tap = false;
  bool verbose = false;  // library frames in tracebacks
};
int test(const TestOptions& options);

struct ScanOptions {
  double timeout = 5;  // seconds
  bool json = false;   // JSON lines instead of a table
  std::vector<std::string> adapters;
};
int scan(const ScanOptions& options);

// pitwall bridge: the cars (simulated, or --ble) on an MQTT broker under the seed's topic tree.
struct BridgeOptions : CarSource {
  std::string hostId;  // empty: the machine's host name
  bool readOnly = false;
  std::optional<double> duration;  // seconds; none: until SIGINT/SIGTERM
};
int bridge(const BridgeOptions& options);

// pitwall view --mqtt URL: a spectator — the race view of the cars that bridges publish on the
// broker, read-only (nothing is ever published). --track is the layout drawn (docs/view.md).
struct ViewOptions : CarSource {
  std::optional<double> duration;  // seconds; none: until SIGINT/SIGTERM
};
int view(const ViewOptions& options);

// A BLE peripheral that looks like an Anki car to a central, driven by the simulator
// (tests/qemu: the real bluetoothd end to end).
struct EmulateOptions {
  std::string adapter = "hci0";
  std::string name = "pitwall";
  // The advertised local name: false — laid out as a car's (state, version, filler, name;
  // anki::localNameText), which clients that read the state byte need; true — the name alone.
  bool plainName = false;
  std::uint8_t model = 8;  // Groundshock
  std::string track = "oval";
  std::uint64_t seed = 1;
  std::string sensor = "real";  // --sensor real|ideal (docs/simulator.md "Sensor model")
  std::uint16_t firmware = anki::kFirmwareDefault;  // --firmware (docs/simulator.md)
  std::optional<double> duration;                   // seconds; none: until SIGINT/SIGTERM
};
int emulateCar(const EmulateOptions& options);

// pitwall replay FILE: a --record file played back through the codec and the car model
// (docs/view.md "Replays"): a summary per car, the race view, or a script's handlers.
struct ReplayOptions {
  std::string file;
  bool summary = false;  // --summary: the table per car (the default without --view, --script)
  bool json = false;     // --json: the summary as one JSON object per car per line
  std::optional<std::string> view;  // --view [[HOST:]PORT]: play it in the race view, real time
  double speed = 1;                 // --speed X with --view: 0.1..100
  // --track: the layout the view draws; none: the record's own ("layout" on its first line),
  // else oval (a record written before records kept their layout)
  std::optional<std::string> track;
  std::string script;      // --script S.lua: the recorded events reach its handlers
  std::uint64_t seed = 1;  // the script's math.random
  // --interval S: a capture without times has a frame every S seconds (else they are inferred)
  std::optional<double> interval;
};
int replay(const ReplayOptions& options);

// pitwall track show LAYOUT|FILE [--svg OUT]: a layout's summary, and its drawing as SVG.
struct TrackShowOptions {
  std::string layout;
  std::string svg;  // empty: none; "-": stdout
};
int trackShow(const TrackShowOptions& options);
// pitwall track list: the named layouts and Anki's stock pieces, on stdout.
int trackList();

// pitwall track print / track verify (docs/cli.md): run by the print module, loaded for them
// alone (engine/print/commands.hpp, engine/cli/print_module.hpp).
using TrackPrintOptions = print::PrintRequest;
int trackPrint(const TrackPrintOptions& options);
using TrackVerifyOptions = print::VerifyRequest;
int trackVerify(const TrackVerifyOptions& options);

int decode(const std::string& protocol, const std::vector<std::string>& hex);
int encode(const std::string& protocol, const std::vector<std::string>& words);

// The seed robots' codecs from the shell (docs/robots.md): the bytes are already parsed from hex;
// print JSON (decode) or hex (encode) on stdout, or the error on stderr with status 2.
int decodeMindroad(const std::vector<std::uint8_t>& bytes);
int encodeMindroad(const std::vector<std::string>& words);
int decodeAlphabot(const std::vector<std::uint8_t>& bytes, const std::string& side);
int encodeAlphabot(const std::vector<std::string>& words);

// pitwall sim-robot mindroad|alphabot --listen HOST:PORT: the robot side, simulated.
struct SimRobotOptions {
  std::string kind;                    // "mindroad" or "alphabot"
  std::string listen = "127.0.0.1:0";  // port 0: any free port, printed on stdout
  bool udp = false;                    // mindroad: UDP instead of TCP
  double watchdog = 0.5;               // mindroad: seconds without an instruction before it stops
  std::uint64_t seed = 1;
  std::optional<double> duration;  // seconds; none: until SIGINT/SIGTERM
  std::string room;                // alphabot: a room file; empty: the default room
};
int simRobot(const SimRobotOptions& options);
int simRobotMindroad(const SimRobotOptions& options);
int simRobotAlphabot(const SimRobotOptions& options);

}  // namespace pitwall::cli
