#include "engine/cli/session.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "bindings/car_binding.hpp"
#include "bindings/interrupt.hpp"
#include "bindings/sandbox.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/core/console.hpp"
#include "engine/core/data_dir.hpp"
#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/sim/grid.hpp"
#include "engine/transport/sim_link.hpp"

namespace pitwall::cli {

// Long enough for a frame to cross the simulator link and be acted on.
constexpr Duration kFlush = std::chrono::milliseconds(100);

Session::Session(ClockKind clock, sim::Track track, std::uint64_t seed)
    : loop_(clock), fleet_(loop_) {
  sim_.seed = seed;
  sim_.world = std::make_unique<sim::World>(loop_, std::move(track), seed);
  log::setTimeSource([this] { return loop_.seconds(); });
}

Session::Session(ble::CentralOptions options) : loop_(ClockKind::Real), fleet_(loop_) {
  log::setTimeSource([this] { return loop_.seconds(); });
  central_ = std::make_unique<ble::Central>(loop_, fleet_, std::move(options));
}

Session::Session(ClockKind clock) : loop_(clock), fleet_(loop_) {
  log::setTimeSource([this] { return loop_.seconds(); });
}

// The subsystems go in the reverse of their declaration (session.hpp): the Lua world first,
// then the view, the seats' holders, MQTT, the radio, the record, the fleet, the loop last. Only
// the signal handlers and the watchdog go before the record's last flush.
Session::~Session() {
  watchdog_.reset();
  signals_.reset();
  if (recorder_) recorder_->flush();
}

std::unique_ptr<Session> Session::open(const CarSource& source, bool fast, const char* command) {
  std::unique_ptr<Session> session;
  if (!source.ble) {
    auto track = sim::loadLayout(source.track);
    if (!track) {
      fail(command, track.error());
      return nullptr;
    }
    if (source.cars > sim::gridCapacity(*track)) {
      // A grid that wraps would put cars on top of each other (docs/simulator.md "The grid").
      std::string fits = std::to_string(source.cars) + " cars do not fit the grid of " +
                         source.track + ", which holds " +
                         std::to_string(sim::gridCapacity(*track)) + " (four on each piece)";
      std::string longer = sim::ovalLayoutFor(source.cars);
      if (source.trackGiven) {
        fail(command,
             fits + "; give a layout of at least " + std::to_string((source.cars + 3) / 4) +
                 " pieces, or leave out --track for an oval that holds them (" + longer + ")");
        return nullptr;
      }
      track = sim::parseLayout(longer, "oval");
      if (!track) {  // ovalLayoutFor's layouts close (world_test): a bug if this is reached
        fail(command, "internal error: " + track.error());
        return nullptr;
      }
      char lap[32];
      std::snprintf(lap, sizeof lap, "%.1f m", track->lapLength(0) / 1000);
      log::info("pitwall", fits + ": racing on an oval of " + std::to_string(track->size()) +
                               " pieces instead, " + lap + " a lap");
    }
    session = std::make_unique<Session>(fast ? ClockKind::Virtual : ClockKind::Real,
                                        std::move(*track), source.seed);
    session->sim().world->setSensor(
        sim::sensorModelNamed(source.sensor).value_or(sim::SensorModel::Real));
  } else {
    // Real cars on printed pieces: the layout tells the scripts the custom pieces' shapes.
    std::optional<sim::Track> design;
    if (source.trackGiven) {
      auto track = sim::loadLayout(source.track);
      if (!track) {
        fail(command, track.error());
        return nullptr;
      }
      design = std::move(*track);
    }
    ble::CentralOptions central;
    central.adapters = source.adapters;
    central.cars = source.carAddresses;
    central.scan = fromSeconds(source.scanTimeout);
    central.carsPerAdapter = source.carsPerAdapter;
    try {
      session = std::make_unique<Session>(std::move(central));
      session->design_ = std::move(design);
      session->sim_.seed = source.seed;  // (a --ghost's world beside the real cars)
    } catch (const ble::BleError& e) {
      fail(command, e.what());
      return nullptr;
    }
  }
  session->source_ = source;
  session->limitsFromSource_ = true;
  session->catchSignals();
  return session;
}

std::unique_ptr<Session> Session::openReplay(ClockKind clock) {
  auto session = std::make_unique<Session>(clock);
  session->catchSignals();
  session->spectate();  // a record's cars: the end of the replay has nothing to stop
  return session;
}

namespace {
// In the signal handler: the Lua code running now is interrupted, so that a busy callback does
// not hold the stop up (with or without the callback budget).
void interruptLua() {
  interrupt::requestFromSignal();
}
}  // namespace

void Session::catchSignals() {
  StopSignals::setAsyncHook(interruptLua);
  signals_ = std::make_unique<StopSignals>(loop_);
  // The stop that does not need the loop: a real-time loop that has not turned for a second
  // (C code that never returns, a stall) gets every car stopped from a thread of its own.
  // $PITWALL_WATCHDOG sets the seconds (0: none), for tests of the last-resort exit alone.
  if (loop_.clockKind() == ClockKind::Real) {
    double seconds = 1;
    if (const char* env = std::getenv("PITWALL_WATCHDOG"); env && *env) {
      char* end = nullptr;
      double given = std::strtod(env, &end);
      if (end && !*end && given >= 0 && given <= 86400)
        seconds = given;
      else
        log::warn("pitwall", std::string("$PITWALL_WATCHDOG is not a number of seconds from 0 to "
                                         "86400: ") +
                                 env + "; the watchdog waits 1 s");
    }
    if (seconds > 0)
      watchdog_ = std::make_unique<Watchdog>(
          loop_, std::chrono::milliseconds(std::llround(seconds * 1000)));
    // Falling behind real time is said, once, with what to do (docs/simulator.md "Real time").
    lag_ = std::make_unique<LagMonitor>(loop_);
    lag_->onBehind = [](double meanLateMs) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "the engine is falling behind real time: its loop ran %.0f ms late on average "
                    "over the last 2 s (long Lua callbacks, or a machine too busy); cars and "
                    "timers are seen late. Give the callbacks less to do, close other programs, "
                    "or race the simulator in virtual time (--fast)",
                    meanLateMs);
      log::warn("pitwall", text);
    };
    lag_->onCaughtUp = [] { log::info("pitwall", "the engine keeps up with real time again"); };
  }
  signals_->onSignal = [this](int sig, int count) {
    if (sig == SIGTSTP) return suspend();
    if (sig == SIGPIPE) {
      outputGone_ = interrupted_ = true;
      log::warn("pitwall",
                "the output's reader went away (a pipe closed: head, grep -m, a quit less, a "
                "dropped connection): stopping the cars; the rest of the output is dropped");
      return finish();
    }
    if (count >= 2) {  // a second one: leave now, the stops sent all the same
      log::warn("pitwall", "leaving now");
      if (scripts_) scripts_->shutDown();
      fleet_.haltAll();
      if (recorder_) recorder_->flush();
      loop_.stop();
      return;
    }
    interrupted_ = true;
    // (a spectator — a replay, a view of another host's cars — has no car of its own to stop)
    log::warn("pitwall", std::string(sig == SIGINT   ? "interrupted"
                                     : sig == SIGHUP ? "hung up"
                                                     : "terminated") +
                             (spectator_ ? ": the end" : ": stopping the cars"));
    finish();
  };
}

// Ctrl-Z: the cars first, the process after, as a game pauses. The cars get their stop and
// refuse every command while the stops travel (100 ms, kFlush: a script that commands them
// every 20 ms cannot send them off again); then the process suspends itself. `fg` resumes the
// engine — timers, the script, the view — and never the cars: they take commands again and stay
// stopped until the script or a driver gives one.
void Session::suspend() {
  if (suspending_) return;
  suspending_ = true;
  const bool cars = !finishing_ && !spectator_;
  if (cars) fleet_.pauseAll("the run is suspended (Ctrl-Z)");
  log::warn("pitwall", cars ? "suspended (Ctrl-Z): the cars are stopped; fg resumes the run, and "
                              "the cars stay stopped until the script or a driver commands them"
                            : "suspended (Ctrl-Z)");
  if (recorder_) recorder_->flush();
  loop_.after(kFlush, [this] {
    if (recorder_) recorder_->flush();
    std::cout.flush();
    std::fflush(stdout);
    if (watchdog_) watchdog_->hold(true);  // a suspended loop is not a stuck one
    // and, with no Lua code left to run before the stop, every stop outside the loop: the
    // robots the fleet does not hold (an Alphabot, a MindRoad robot) get theirs too
    if (!finishing_ && !spectator_) {
      emergency::sendAll();
      emergency::runStoppers();
    }
    ::raise(SIGSTOP);  // here until SIGCONT (fg, bg, kill -CONT)
    if (watchdog_) watchdog_->hold(false);
    suspending_ = false;
    if (finishing_) return;
    fleet_.resumeAll();
    log::info("pitwall", "resumed: the cars take commands again");
  });
}

void Session::releaseSigint() {
  if (signals_) signals_->releaseSigint();
}

int Session::exitStatus(int otherwise) {
  if (scripts_ && host().exitStatus()) return *host().exitStatus();
  if (outputGone_) return 141;  // as a process that SIGPIPE ended (128 + 13), after the stop
  if (interrupted_) return 130;
  return otherwise;
}

namespace {

// The client's options from the command line; an error sentence names the option at fault.
Result<MqttOptions, std::string> mqttOptions(const MqttSettings& settings) {
  MqttOptions options;
  try {
    options = MqttOptions::fromUrl(settings.url);
  } catch (const std::invalid_argument& e) {
    return Unexpected{std::string("--mqtt: ") + e.what()};
  }
  options.clientId = settings.clientId;
  options.username = settings.user;
  if (!settings.passwordFile.empty()) {
    std::ifstream in(settings.passwordFile);
    if (!in || !std::getline(in, options.password))
      return Unexpected{"--mqtt-password-file: cannot read a password from " +
                        settings.passwordFile};
    if (!options.password.empty() && options.password.back() == '\r') options.password.pop_back();
  } else if (const char* env = std::getenv("PITWALL_MQTT_PASSWORD")) {
    options.password = env;
  }
  if (!options.password.empty() && options.username.empty())
    return Unexpected{std::string(settings.passwordFile.empty() ? "$PITWALL_MQTT_PASSWORD"
                                                                : "--mqtt-password-file") +
                      " gives a password without --mqtt-user"};
  options.caFile = settings.caFile;
  if (!options.caFile.empty() && !options.tls)
    return Unexpected{"--mqtt-ca needs an mqtts:// URL (TLS)"};
  return options;
}

std::string machineName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || !name[0]) return "pitwall";
  return name;
}

}  // namespace

int Session::startBridge(const MqttSettings& settings, const std::string& hostId, bool readOnly,
                         const char* command) {
  auto options = mqttOptions(settings);
  if (!options) {
    return fail(command, options.error());
  }
  std::string host = topics::hostId(hostId.empty() ? machineName() : hostId);
  options->will = MqttBridge::will(host);
  CarConnections connections;
  connections.connectAll = [this] {
    if (central_) return central_->reconnect();
    for (auto* car : fleet_.cars())
      if (auto* sim = dynamic_cast<SimLink*>(&car->link()); sim && !sim->connected())
        sim->connect();
  };
  connections.disconnectAll = [this] {
    if (central_) return central_->shutdown(nullptr);
    for (auto* car : fleet_.cars())
      if (car->state().connected) (void)car->disconnect();
  };
  try {
    mqtt_ = std::make_unique<MqttClient>(loop_, std::move(*options));
    bridge_ = std::make_unique<MqttBridge>(
        loop_, fleet_, *mqtt_,
        pitwall::BridgeOptions{host, readOnly, topics::PayloadLimits{settings.maxPayload}},
        std::move(connections));
  } catch (const std::invalid_argument& e) {
    return fail(command, e.what());
  }
  // The first answer decides: a refusal (credentials, authorisation) ends the bridge; a broker
  // that cannot be reached yet is retried for as long as the bridge runs.
  std::optional<std::string> refused;
  bool answered = false;
  mqtt_->onDisconnected = [&](const std::string& reason, bool retrying) {
    if (!retrying) refused = reason;
    answered = true;
    loop_.stop();
  };
  auto previousConnected = mqtt_->onConnected;
  mqtt_->onConnected = [&] {
    if (previousConnected) previousConnected();
    answered = true;
    loop_.stop();
  };
  mqtt_->connect();
  // A broker that refuses at once (nobody listens on the port) answers inside connect(): the
  // loop's stop() came before run(), which would forget it.
  if (!answered) {
    loop_.runAtMost(fromSeconds(source_.mqttTimeout));
  }
  mqtt_->onConnected = previousConnected;
  mqtt_->onDisconnected = nullptr;  // the client logs why; it reconnects by itself
  if (interrupted_) return 130;
  if (refused) {
    return fail(command, "the broker refused the connection: " + *refused);
  }
  return 0;
}

int Session::connectRemoteCars(const char* command) {
  auto options = mqttOptions(source_.mqtt);
  if (!options) {
    return fail(command, options.error());
  }
  try {
    mqtt_ = std::make_unique<MqttClient>(loop_, std::move(*options));
  } catch (const std::invalid_argument& e) {
    return fail(command, e.what());
  }
  remote_ = std::make_unique<RemoteCars>(loop_, fleet_, *mqtt_,
                                         topics::PayloadLimits{source_.mqtt.maxPayload});
  remote_->setReadOnly(spectator_);
  // The callbacks outlive this wait (a late sync, a refusal on a later reconnection): they share
  // this state and do nothing once the wait is over.
  struct Start {
    bool waiting = true, synced = false;
    std::optional<std::string> failed;
  };
  auto start = std::make_shared<Start>();
  auto enough = [this, start] {
    return start->synced && remote_->onlineCount() >= static_cast<std::size_t>(source_.remoteCars);
  };
  remote_->onChange = [this, enough] {
    if (enough()) loop_.stop();
  };
  remote_->start(
      [this, start, enough] {
        start->synced = true;
        if (start->waiting && enough()) loop_.stop();
      },
      [this, start](const std::string& reason) {
        if (!start->waiting) return;
        start->failed = reason;
        loop_.stop();
      });
  loop_.runAtMost(fromSeconds(source_.mqttTimeout));
  start->waiting = false;
  remote_->onChange = nullptr;
  const bool synced = start->synced;
  const auto& failed = start->failed;
  if (interrupted_) return 130;
  std::string where = " (" + source_.mqtt.url + ")";
  if (failed) {
    return fail(command, "the broker refused the connection" + where + ": " + *failed);
  }
  if (!synced) {
    const std::string timeout = formatNumber(source_.mqttTimeout) + " s";
    if (mqtt_->state() == MqttClient::State::Connected)
      return fail(command, "the MQTT broker" + where +
                               " did not return pitwall's sync message in " + timeout +
                               " (does its access control allow pitwall/sync/#?)");
    return fail(command, "no connection to the MQTT broker" + where + " in " + timeout);
  }
  if (!enough()) {
    return fail(command, std::to_string(remote_->onlineCount()) + " remote car" +
                             (remote_->onlineCount() == 1 ? "" : "s") + " online after " +
                             formatNumber(source_.mqttTimeout) + " s, --remote-cars asked for " +
                             std::to_string(source_.remoteCars));
  }
  log::info("mqtt", std::to_string(remote_->onlineCount()) + " remote car" +
                        (remote_->onlineCount() == 1 ? "" : "s") + " through " + source_.mqtt.url);
  return 0;
}

int Session::connectCars(const char* command) {
  int status = connectLocalCars(command);
  if (status == 0 && !source_.mqtt.url.empty()) status = connectRemoteCars(command);
  // A start refused once some cars are connected (too few remote cars, a broker that refused or
  // never answered, a simulated car that did not connect) still ends through the stop path: the
  // connected cars' last frame is their stop.
  if (status != 0 && !finishing_) {
    finish();
    loop_.run();
  }
  return status;
}

int Session::connectLocalCars(const char* command) {
  if (source_.ble) {
    auto error = connectRealCars();
    if (interrupted_) return 130;
    if (error) {
      fail(command, *error);
      finish();
      loop_.run();
      return 2;
    }
    if (!addGhost()) {
      if (interrupted_) return 130;
      return fail(command, "the ghost did not connect", 1);
    }
    return 0;
  }
  if (!addGridCars(source_.cars)) {
    if (interrupted_) return 130;
    return fail(command, "not every simulated car connected", 1);
  }
  if (!addGhost()) {
    if (interrupted_) return 130;
    return fail(command, "the ghost did not connect", 1);
  }
  return 0;
}

const sim::Track* Session::ghostTrack() const {
  if (sim_.world) return &sim_.world->track();
  return design_ ? &*design_ : nullptr;
}

// A simulated car, the ghost's, joins the fleet as the grid's cars do; beside real cars it
// drives a world of its own on their layout (it touches no one, so it needs no one else there).
bool Session::addGhost() {
  if (!ghost_) return true;
  sim::World* world = sim_.world.get();
  if (!world) {
    ghostWorld_ = std::make_unique<sim::World>(loop_, *design_, sim_.seed);
    world = ghostWorld_.get();
  }
  sim::CarSpec spec = std::move(*ghost_);
  ghost_.reset();
  spec.version = source_.firmware;
  if (!awaitJoined({&joinSimCar(*world, spec, true)})) return false;
  log::info("pitwall", spec.name + " drives " + ghostWhat_ + " again, from the green light");
  return true;
}

void Session::record(const std::string& path) {
  recorder_ = std::make_unique<Recorder>(path, Recorder::Later{});
  flushRecordPeriodically();
  // What a replay needs beside the frames (docs/cli.md "Record format"): the layout on the
  // record's first line, each car's "carName" on its first line.
  auto named = std::make_shared<std::set<int>>();
  auto layout = std::make_shared<std::string>(
      sim_.world ? ",\"layout\":" + nlohmann::json(sim::layoutText(sim_.world->track())).dump()
                 : "");
  recording_ = fleet_.frames.connect([this, named, layout](AnkiCar& car, AnkiCar::Direction d,
                                                           std::span<const std::uint8_t> f,
                                                           const anki::Message& m) {
    std::string extra = std::exchange(*layout, {});
    if (named->insert(car.identity().number).second)
      extra +=
          ",\"carName\":" + nlohmann::json(car.identity().name)
                                .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    recorder_->write(loop_.seconds(), car.identity().number, d == AnkiCar::Direction::Tx, f, m,
                     extra);
  });
  // The link's health at each drop and each connection (a replay shows it as it was); not the
  // cars let go at the end of the run, which is no drop
  linkRecording_ =
      fleet_.connectionChanged.connect([this](AnkiCar& car, bool up, const std::string& reason) {
        if (finishing_) return;
        nlohmann::json link = view::linkJson(car);  // as the view has it, and up or down
        link["up"] = up;
        link["reason"] = up ? nlohmann::json(nullptr) : nlohmann::json(reason);
        recorder_->writeLink(loop_.seconds(), car.identity().number,
                             link.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
      });
}

// The race into the record, for a replay's view (docs/cli.md "Record format"): every change of
// phase or title at once, else at most twice a second (a race reports ten times a second); each
// car's lap times, the latest kRaceLapsRecorded of them (lapTimesFrom numbers the first), so that
// a line stays short in a race of a thousand laps.
void Session::recordRace(const nlohmann::json& race) {
  constexpr double kEvery = 0.5;
  constexpr std::size_t kRaceLapsRecorded = 100;
  const double now = loop_.seconds();
  auto key = [](const nlohmann::json& r) {
    if (!r.is_object()) return std::string("null");
    return r.value("phase", nlohmann::json()).dump() + r.value("title", nlohmann::json()).dump();
  };
  const std::string k = key(race);
  if (k == raceKey_ && now - raceWritten_ < kEvery) return;
  raceKey_ = k;
  raceWritten_ = now;
  constexpr auto kReplace = nlohmann::json::error_handler_t::replace;
  auto laps = race.is_object() ? race.find("lapTimes") : race.end();
  if (laps == race.end() || !laps->is_object()) {
    recorder_->writeRace(now, race.dump(-1, ' ', false, kReplace));
    return;
  }
  nlohmann::json shown = race;
  nlohmann::json from = nlohmann::json::object();
  for (auto& [car, times] : shown["lapTimes"].items()) {
    if (!times.is_array() || times.size() <= kRaceLapsRecorded) continue;
    const std::size_t cut = times.size() - kRaceLapsRecorded;
    times.erase(times.begin(), times.begin() + static_cast<std::ptrdiff_t>(cut));
    from[car] = cut + 1;
  }
  if (!from.empty()) shown["lapTimesFrom"] = std::move(from);
  if (!recorder_->writeRace(now, shown.dump(-1, ' ', false, kReplace)) && !raceTooLong_) {
    raceTooLong_ = true;
    log::warn("record",
              "the race's state is longer than a record's line (64 KiB): left out of "
              "the record from now on; the frames are all there");
  }
}

void Session::openRecord() {
  if (recorder_) recorder_->open();
}

// A killed run loses at most the last 100 ms of its record: in real time the record reaches
// the file every 50 ms even when no frame comes (Recorder::write flushes as frames come, which
// covers virtual time, where a timer here would keep the loop from ever running dry).
void Session::flushRecordPeriodically() {
  if (loop_.clockKind() != ClockKind::Real || finishing_) return;
  loop_.after(std::chrono::milliseconds(50), [this] {
    if (!recorder_) return;
    recorder_->flush();
    flushRecordPeriodically();
  });
}

bool Session::addGridCars(int count) {
  std::vector<std::string> names;
  std::vector<const AnkiCar*> cars;
  for (int i = 0; i < count; ++i) {
    sim::CarSpec spec = sim::gridSpec(sim_.world->track(), i);
    spec.name = anki::uniqueCarName(spec.model_id, names);
    spec.version = source_.firmware;
    names.push_back(spec.name);
    cars.push_back(&joinSimCar(*sim_.world, spec, false));
  }
  return awaitJoined(cars);
}

// A simulated car joins the fleet over a SimLink, which connects once the fleet listens.
AnkiCar& Session::joinSimCar(sim::World& world, const sim::CarSpec& spec, bool ghost) {
  sim::SimCar& simCar = world.addCar(spec);
  auto link = std::make_unique<SimLink>(loop_, simCar);
  SimLink& toCar = *link;
  AnkiCar& car = fleet_.add(std::move(link),
                            CarIdentity{0, spec.name, spec.model_id, simCar.identifier(), ghost});
  toCar.connect();
  return car;
}

// Runs the loop until each of `cars` is connected, for 5 s at most.
bool Session::awaitJoined(const std::vector<const AnkiCar*>& cars) {
  auto all = [&] {
    return std::ranges::all_of(cars, [](const AnkiCar* c) { return c->state().connected; });
  };
  if (all()) return true;
  Subscription joined = fleet_.carJoined.connect([&](AnkiCar&) {
    if (all()) loop_.stop();
  });
  loop_.runAtMost(std::chrono::seconds(5));
  return all();
}

std::optional<std::string> Session::connectRealCars() {
  std::optional<std::string> result = "interrupted";
  central_->start([&](std::optional<std::string> error) {
    result = std::move(error);
    loop_.stop();
  });
  loop_.run();
  return result;
}

void Session::startHost(HostOptions options) {
  if (limitsFromSource_) {  // a run, a REPL: the world's limits are the command line's
    options.budget = std::chrono::milliseconds(std::llround(source_.budget * 1000));
    options.memory_limit = static_cast<std::size_t>(source_.luaMemory) << 20;
    options.handler_errors = {source_.handlerErrors, source_.handlerErrorsWindow};
  }
  if (!sim_.world && design_) options.design = &*design_;
  if (recorder_) options.recordRace = [this](const nlohmann::json& race) { recordRace(race); };
  scripts_ =
      std::make_unique<Reloader>(loop_, fleet_, sim_.world ? &sim_ : nullptr, std::move(options));
  scripts_->onStopRequested = [this] { finish(); };
}

int Session::startView(const std::string& endpoint, const std::string& source,
                       const char* command) {
  auto options = view::parseEndpoint(endpoint);
  if (!options) {
    return fail(command, options.error() +
                             " (--view takes an optional [HOST:]PORT: write --view=PORT, or put "
                             "--view after the script)");
  }
  auto assets = view::findAssets();
  if (!assets) {
    return fail(command, assets.error());
  }
  options->assets = *assets;
  options->names = viewHosts();
  options->classroom = classroom_.get();
  options->tests = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  startFeed(source);
  feed_->followLog(true);
  server_ = std::make_unique<view::Server>(loop_, *feed_, *options);
  if (auto started = server_->start(); !started) {
    fail(command, started.error());
    server_.reset();
    feed_.reset();
    return 2;
  }
  console::noteOutput();
  std::cerr << "view: " << server_->url() << "\n";
  if (server_->joinCode().empty() || source == "mqtt") {
    // loopback: no code; a spectator (pitwall view): nothing to drive or control
  } else if (source == "replay") {  // docs/view.md "Pairing": only invited people control it
    std::cerr << "view: join code " << server_->joinCode()
              << ": the replay's controls are for pages opened as " << server_->viewUrl() << "\n";
  } else {  // docs/view.md "Pairing": only invited people drive
    std::cerr << "view: join code " << server_->joinCode() << ": to drive, phones open "
              << server_->driveUrl() << "\n";
  }
  if (classroom_) {  // docs/classroom.md
    std::cerr << "code: students open " << server_->codeUrl()
              << (server_->joinCode().empty() ? "" : " (join code " + server_->joinCode() + ")")
              << "\ncode: the teacher's page (keep it to yourself): " << server_->teacherUrl()
              << "\n";
  }
  if (options->host != "127.0.0.1" && options->host != "::1")
    log::warn("view", "serving on " + options->host +
                          ": anyone who can reach this machine can watch (read-only); driving "
                          "and replay controls need the join code");
  return 0;
}

int Session::openClassroom(const std::string& folder, const char* command) {
  auto data = dataDir();
  if (!data) return fail(command, data.error());
  const auto starterPath = *data / "examples" / "classroom" / "starter.lua";
  std::ifstream f(starterPath, std::ios::binary);
  if (!f)
    return fail(command, "cannot read the classroom's starter driver " + starterPath.string());
  std::ostringstream starter;
  starter << f.rdbuf();
  classroom_ = std::make_unique<classroom::Classroom>(loop_, folder, starter.str());
  if (auto ok = classroom_->prepare(); !ok) {
    classroom_.reset();
    return fail(command, ok.error());
  }
  return 0;
}

Result<std::map<int, std::string>, std::string> Session::addDesks() {
  std::map<int, std::string> files;
  for (AnkiCar* car : fleet_.cars()) {
    if (car->identity().ghost) continue;  // (no one codes a ghost's driver)
    const int n = car->identity().number;
    if (auto ok = classroom_->addDesk(n, car->identity().name); !ok) return Unexpected{ok.error()};
    files[n] = classroom_->driverFile(n).string();
  }
  return files;
}

int Session::startSeats(const CarSource& source, const char* command) {
  if (source.humans <= 0) return 0;
  seats_ = std::make_unique<drive::Seats>(loop_, fleet_, source.humans);
  if (feed_) feed_->setSeats(seats_.get());  // phones take seats on the view's /drive page
  if (source.gamepads) {
    drive::GamepadsOptions options;
    if (const char* dir = std::getenv("PITWALL_INPUT_DIR"); dir && *dir) options.folder = dir;
    gamepads_ = std::make_unique<drive::Gamepads>(loop_, *seats_, options);
    if (auto started = gamepads_->start(); !started) {
      return fail(command, started.error());
    }
  }
  if (source.keyboard) {
    keyboard_ = std::make_unique<drive::Keyboard>(loop_, *seats_, 0);
    if (auto started = keyboard_->start(); !started) {
      return fail(command, started.error());
    }
  }
  const std::string cars =
      source.humans == 1 ? "car 1" : "cars 1.." + std::to_string(source.humans);
  if (server_) {
    console::noteOutput();
    std::cerr << "drive: " << server_->driveUrl() << " (" << cars << ": one phone a car)\n";
    if (!server_->joinCode().empty())
      log::info("seats", "a phone takes a seat of " + cars + " only with the join code " +
                             server_->joinCode() + " (docs/view.md \"Pairing\")");
  } else if (!source.gamepads && !source.keyboard) {
    log::warn("seats", "--humans " + std::to_string(source.humans) +
                           " and nothing to hold the seats but a script: add --view (phones on "
                           "its /drive page), --gamepads or --keyboard");
  }
  return 0;
}

view::Feed& Session::startFeed(const std::string& source) {
  if (!feed_) {
    feed_ = std::make_unique<view::Feed>(loop_, fleet_, source);
    if (sim_.world)
      feed_->setTrack(sim_.world->track(), "layout");
    else if (design_)
      feed_->setTrack(*design_, "layout");
  }
  return *feed_;
}

void Session::finish() {
  if (finishing_) return;
  finishing_ = true;
  // First the script: from here nothing of it runs, so nothing it does can follow the stop.
  if (scripts_) scripts_->shutDown();
  // Then every car's stop, the last command it takes (AnkiCar::halt); a spectator's cars are
  // other hosts' and get nothing from it.
  if (!spectator_) fleet_.haltAll();
  // The terminal back to itself, the gamepads closed: nothing holds a seat any more.
  keyboard_.reset();
  gamepads_.reset();
  // A race cut short says where it stood: the final table, the results (nothing can drive now).
  if (scripts_) scripts_->lastWords();
  if (recorder_) recorder_->flush();
  loop_.after(kFlush, [this] {
    auto done = [this] {
      if (!mqtt_) return loop_.stop();
      auto disconnect = [this] {
        mqtt_->disconnect();
        loop_.after(kFlush, [this] { loop_.stop(); });
      };
      if (!bridge_) return mqtt_->whenDelivered(disconnect);
      // A clean goodbye: the bridge says its cars and itself are offline (the broker drops the
      // will on DISCONNECT), and is gone so that nothing else is published; DISCONNECT follows
      // once the broker has acknowledged the goodbye (QoS 1). A broker whose PUBACK meets a
      // closed socket drops the rest of the goodbye and publishes the will (mosquitto 2.0 logs
      // "disconnected due to out of memory").
      bridge_->goOffline();
      bridge_.reset();
      mqtt_->whenDelivered(disconnect);
    };
    if (!central_) return done();
    central_->shutdown(done);
  });
}

}  // namespace pitwall::cli
