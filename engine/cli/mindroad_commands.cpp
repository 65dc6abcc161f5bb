// pitwall decode|encode mindroad and pitwall sim-robot mindroad (docs/robots.md).
#include <boost/asio/signal_set.hpp>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/loop.hpp"
#include "engine/core/numbers.hpp"
#include "engine/protocol/mindroad/codec.hpp"
#include "engine/protocol/mindroad/command_text.hpp"
#include "engine/protocol/mindroad/message_json.hpp"
#include "engine/record/recorder.hpp"
#include "engine/sim/mindroad_robot_server.hpp"

namespace pitwall::cli {

int decodeMindroad(const std::vector<std::uint8_t>& bytes) {
  auto instruction = mindroad::decode(bytes);
  if (instruction) {
    std::cout << mindroad::toJson(*instruction).dump() << "\n";
    return 0;
  }
  // The robot's one answer, K (0x4b), is never a valid instruction (as a header it announces
  // 11 data bytes for buttons), so a lone 0x4b can only be the answer.
  if (mindroad::decodeAnswer(bytes)) {
    std::cout << mindroad::contactAnswerJson().dump() << "\n";
    return 0;
  }
  return fail("decode", instruction.error().message());
}

int encodeMindroad(const std::vector<std::string>& words) {
  auto instruction = mindroad::parseCommand(words);
  if (!instruction) {
    return fail("encode", instruction.error());
  }
  std::cout << toHex(mindroad::encode(*instruction).span()) << "\n";
  return 0;
}

namespace {

constexpr const char* kComponent = "sim-robot";

std::string showNumber(double v) {
  return formatNumber(v, 6);
}

// "127.0.0.1:4000" → host, port; the port may be 0 (any free one).
bool splitAddress(const std::string& text, std::string& host, std::uint16_t& port,
                  std::string& error) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
    error = "--listen '" + text + "' is not HOST:PORT (e.g. 127.0.0.1:4000, port 0: any free one)";
    return false;
  }
  host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  const std::string digits = text.substr(colon + 1);
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc{} || end != digits.data() + digits.size() || value > 65535) {
    error = "--listen port '" + digits + "' is not a port number 0..65535";
    return false;
  }
  port = static_cast<std::uint16_t>(value);
  return true;
}

// One line of JSON per state change (docs/robots.md "State output").
nlohmann::json stateJson(const sim::MindroadRobot& robot, double t, const std::string& event) {
  const auto& s = robot.state();
  auto round = [](double v, double per) { return std::round(v * per) / per; };
  return {{"t", round(t, 1000)},
          {"event", event},
          {"contact", s.contact},
          {"moving", s.moving()},
          {"steer_x", s.steerX},
          {"steer_y", s.steerY},
          {"x_m", round(s.x, 1000)},
          {"y_m", round(s.y, 1000)},
          {"heading_deg", round(s.heading, 10)},
          {"mode", s.mode},
          {"sensitivity", s.sensitivity},
          {"buttons", s.buttons},
          {"picture_mode", mindroad::pictureName(s.picture)},
          {"click", {s.clickX, s.clickY}},
          {"instructions", s.instructions},
          {"contacts", s.contacts},
          {"malformed", s.malformed},
          {"ignored", s.ignored}};
}

}  // namespace

int simRobotMindroad(const SimRobotOptions& options) {
  sim::MindroadServerOptions server;
  std::string error;
  if (!splitAddress(options.listen, server.host, server.port, error)) {
    return fail("sim-robot", error);
  }
  server.udp = options.udp;
  server.robot.watchdog = options.watchdog;

  Loop loop(ClockKind::Real);
  log::setTimeSource([&loop] { return loop.seconds(); });
  std::unique_ptr<sim::MindroadRobotServer> robot;
  try {
    robot = std::make_unique<sim::MindroadRobotServer>(loop, server);
  } catch (const std::exception& e) {
    fail("sim-robot", e.what());
    log::setTimeSource(nullptr);
    return 2;
  }
  auto printState = [&](const std::string& event) {
    std::cout << stateJson(robot->robot(), loop.seconds(), event).dump() << std::endl;
  };
  robot->onChange = [&](const std::string& event, const std::string& detail) {
    log::info(kComponent, detail);
    printState(event);
    if (event == "shutdown") {
      log::info(kComponent, "shut down by the client: exiting");
      robot->close();
      loop.stop();
    }
  };
  std::cout << "listening on " << robot->address() << std::endl;
  log::info(kComponent, std::string("mindroad robot on ") + (server.udp ? "udp " : "tcp ") +
                            robot->address() + ", watchdog " + showNumber(options.watchdog) + " s");

  boost::asio::signal_set signals(loop.io(), SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code& ec, int sig) {
    if (ec) return;
    log::info(kComponent, sig == SIGINT ? "interrupted" : "terminated");
    robot->close();
    loop.stop();
  });
  if (options.duration)
    loop.after(fromSeconds(*options.duration), [&] {
      log::info(kComponent, "the duration is over");
      robot->close();
      loop.stop();
    });
  loop.run();
  robot->robot().advance(loop.seconds());
  printState("exit");
  robot.reset();
  log::setTimeSource(nullptr);
  return 0;
}

}  // namespace pitwall::cli
