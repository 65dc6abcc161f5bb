// The Alphabot from the shell (docs/robots.md): `pitwall decode alphabot HEX`,
// `pitwall decode alphabot-ble CHARACTERISTIC HEX`, `pitwall encode alphabot …` and
// `pitwall sim-robot alphabot --listen HOST:PORT`.
#include <boost/asio/signal_set.hpp>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <iostream>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/alphabot/ble_codec.hpp"
#include "engine/protocol/alphabot/command_text.hpp"
#include "engine/protocol/alphabot/message_json.hpp"
#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "engine/sim/alphabot_robot.hpp"
#include "engine/sim/alphabot_server.hpp"

namespace pitwall::cli {

namespace {

constexpr const char* kComponent = "sim-robot alphabot";

// "127.0.0.1:4000", "[::1]:4000", "localhost:0" → host and port.
bool splitListen(const std::string& text, std::string& host, std::uint16_t& port,
                 std::string& error) {
  auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    error = "--listen '" + text + "' is not HOST:PORT (e.g. 127.0.0.1:0)";
    return false;
  }
  host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  if (host == "localhost") host = "127.0.0.1";
  std::string p = text.substr(colon + 1);
  unsigned value = 0;
  auto [end, ec] = std::from_chars(p.data(), p.data() + p.size(), value);
  if (p.empty() || ec != std::errc() || end != p.data() + p.size() || value > 65535) {
    error = "--listen port '" + p + "' is not a port number 0..65535";
    return false;
  }
  port = static_cast<std::uint16_t>(value);
  return true;
}

}  // namespace

int decodeAlphabot(const std::vector<std::uint8_t>& bytes, const std::string& side) {
  if (!side.empty()) {
    // `pitwall decode alphabot-ble CHARACTERISTIC HEX`: the BLE codec (ble_codec.hpp).
    auto json = alphabot::decodeBle(side, bytes);
    if (!json) {
      return fail("decode", json.error());
    }
    std::cout << json->dump() << "\n";
    return 0;
  }
  auto packet = alphabot::wlan::decode(bytes);
  if (!packet) {
    return fail("decode", packet.error().message());
  }
  nlohmann::json j = std::visit([](const auto& m) { return alphabot::toJson(m); }, *packet);
  std::cout << j.dump() << "\n";
  return 0;
}

int encodeAlphabot(const std::vector<std::string>& words) {
  if (words.size() == 1 && (words[0] == "help" || words[0] == "--list")) {
    for (const auto& f : alphabot::commandForms()) std::cout << f << "\n";
    return 0;
  }
  auto request = alphabot::parseRequest(words);
  if (!request) {
    return fail("encode", request.error());
  }
  std::cout << toHex(alphabot::wlan::encode(*request)) << "\n";
  return 0;
}

int simRobotAlphabot(const SimRobotOptions& options) {
  if (options.udp) {
    return fail("sim-robot", "--udp is for the mindroad robot; the alphabot speaks TCP");
  }
  std::string host, error;
  std::uint16_t port = 0;
  if (!splitListen(options.listen, host, port, error)) {
    return fail("sim-robot", error);
  }
  sim::alphabot::Room room = sim::alphabot::defaultRoom();
  if (!options.room.empty()) {
    auto loaded = sim::alphabot::loadRoom(options.room);
    if (!loaded) {
      return fail("sim-robot", loaded.error());
    }
    room = std::move(*loaded);
  }

  Loop loop(ClockKind::Real);
  log::setTimeSource([&loop] { return loop.seconds(); });
  sim::alphabot::Robot robot(room);
  std::unique_ptr<sim::alphabot::RobotServer> server;
  try {
    server = std::make_unique<sim::alphabot::RobotServer>(loop, robot, host, port);
  } catch (const std::exception& e) {
    fail("sim-robot", e.what());
    log::setTimeSource(nullptr);
    return 2;
  }
  server->onLog = [](const std::string& line) { log::info(kComponent, line); };
  std::cout << "listening on " << host << ":" << server->port() << std::endl;
  log::info(kComponent, "room " + std::to_string(static_cast<int>(room.width)) + " x " +
                            std::to_string(static_cast<int>(room.height)) + " cm, " +
                            std::to_string(room.obstacles.size()) + " obstacle(s); robot at (" +
                            std::to_string(static_cast<int>(room.startX)) + ", " +
                            std::to_string(static_cast<int>(room.startY)) + ")");

  boost::asio::signal_set signals(loop.io(), SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code& ec, int sig) {
    if (ec) return;
    log::info(kComponent, sig == SIGINT ? "interrupted" : "terminated");
    // what the robot was last told, as a test reads it (robot_way_out_test.sh)
    log::info(kComponent, robot.moving() ? "the robot is moving" : "the robot is at rest");
    server->close();
    loop.stop();
  });
  if (options.duration)
    loop.after(fromSeconds(*options.duration), [&] {
      log::info(kComponent, "the duration is over");
      server->close();
      loop.stop();
    });
  loop.run();
  server.reset();
  log::setTimeSource(nullptr);
  return 0;
}

}  // namespace pitwall::cli
