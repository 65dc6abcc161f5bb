// MqttClient against a real mosquitto broker that each test starts on a free loopback port
// (tests/support/mosquitto_broker.hpp), on a real-clock loop.
#include "engine/transport/mqtt_client.hpp"

#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/mosquitto_broker.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
using pitwall::testing::BrokerOptions;
using pitwall::testing::MosquittoBroker;
using pitwall::testing::runFor;
using pitwall::testing::runUntil;

namespace {

struct Received {
  std::string topic, payload;
  bool retained;
};

// Records what a client reports.
struct Probe {
  int connects = 0;
  std::vector<std::pair<std::string, bool>> drops;  // reason, retrying
  std::vector<Received> messages;

  explicit Probe(MqttClient& c) {
    c.onConnected = [this] { ++connects; };
    c.onDisconnected = [this](const std::string& reason, bool retrying) {
      drops.emplace_back(reason, retrying);
    };
    c.onMessage = [this](std::string_view t, std::string_view p, bool r) {
      messages.push_back({std::string(t), std::string(p), r});
    };
  }
  bool has(const std::string& topic, const std::string& payload) const {
    for (const auto& m : messages)
      if (m.topic == topic && m.payload == payload) return true;
    return false;
  }
};

MqttOptions optionsFor(const MosquittoBroker& broker, const std::string& clientId) {
  auto o = MqttOptions::fromUrl(broker.url());
  o.clientId = clientId;
  return o;
}

bool haveOpenssl() {
  return std::system("command -v openssl >/dev/null 2>&1") == 0;
}

// A throwaway CA in `dir` and a server certificate for 127.0.0.1 signed by it (EC keys: fast).
void makeCertificates(const std::string& dir, const std::string& caName) {
  std::string d = "'" + dir + "'";
  std::string cmd = "cd " + d +
                    " && openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes"
                    " -keyout " +
                    caName + ".key -out " + caName + ".crt -days 1 -subj /CN=" + caName +
                    " && openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes"
                    " -keyout server.key -out server.csr -subj /CN=127.0.0.1"
                    " && printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > ext.cnf"
                    " && openssl x509 -req -in server.csr -CA " +
                    caName + ".crt -CAkey " + caName +
                    ".key -CAcreateserial -out server.crt -days 1 -extfile ext.cnf";
  REQUIRE_MESSAGE(std::system(("{ " + cmd + "; } >'" + dir + "/openssl.log' 2>&1").c_str()) == 0,
                  "openssl could not make the test certificates (see " << dir << "/openssl.log)");
}

}  // namespace

TEST_CASE("mqtt: parseMqttUrl reads mqtt:// and mqtts:// with default ports") {
  auto plain = parseMqttUrl("mqtt://broker.local");
  REQUIRE(plain.ok());
  CHECK(plain->host == "broker.local");
  CHECK(plain->port == 1883);
  CHECK_FALSE(plain->tls);
  auto secure = parseMqttUrl("mqtts://10.0.0.2");
  REQUIRE(secure.ok());
  CHECK(secure->port == 8883);
  CHECK(secure->tls);
  auto withPort = parseMqttUrl("mqtt://127.0.0.1:1999/");
  REQUIRE(withPort.ok());
  CHECK(withPort->port == 1999);
  auto v6 = parseMqttUrl("mqtts://[::1]:8884");
  REQUIRE(v6.ok());
  CHECK(v6->host == "::1");
  CHECK(v6->port == 8884);
}

TEST_CASE("mqtt: a bad URL is refused with a message naming what is wrong") {
  auto error = [](const char* url) {
    auto r = parseMqttUrl(url);
    REQUIRE_FALSE(r.ok());
    return r.error();
  };
  CHECK(error("http://host").find("unknown scheme 'http'") != std::string::npos);
  CHECK(error("broker:1883").find("no scheme") != std::string::npos);
  CHECK(error("mqtt://").find("no host") != std::string::npos);
  CHECK(error("mqtt://host:").find("empty port") != std::string::npos);
  CHECK(error("mqtt://host:http").find("port 'http'") != std::string::npos);
  CHECK(error("mqtt://host:70000").find("port '70000'") != std::string::npos);
  CHECK(error("mqtt://host:1883/topic").find("unexpected '/topic'") != std::string::npos);
  CHECK(error("mqtt://user:pw@host").find("credentials") != std::string::npos);
  CHECK(error("mqtt://::1:1883").find("brackets") != std::string::npos);
  CHECK_THROWS_WITH_AS(MqttOptions::fromUrl("tcp://h"), doctest::Contains("mqtt://HOST[:PORT]"),
                       std::invalid_argument);
}

TEST_CASE("mqtt: bad options and bad topics are refused before anything is sent") {
  Loop loop(ClockKind::Real);
  MqttOptions o;
  o.keepaliveSeconds = 1;
  CHECK_THROWS_WITH_AS(MqttClient(loop, o), doctest::Contains("keepalive 1 s"),
                       std::invalid_argument);
  o = {};
  o.caFile = "/nonexistent/ca.crt";
  o.tls = true;
  CHECK_THROWS_WITH_AS(MqttClient(loop, o), doctest::Contains("cannot read the CA file"),
                       std::invalid_argument);
  o = {};
  o.will = MqttWill{"a/+/b", "x", 1, false};
  CHECK_THROWS_WITH_AS(MqttClient(loop, o), doctest::Contains("not a valid MQTT topic"),
                       std::invalid_argument);
  MqttClient client(loop, MqttOptions{});
  CHECK_THROWS_WITH_AS(client.publish("a/#", "x"), doctest::Contains("'a/#'"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(client.publish("a", "x", 3), doctest::Contains("QoS 3"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(client.subscribe("a/#/b"), doctest::Contains("not a valid topic filter"),
                       std::invalid_argument);
  CHECK_FALSE(client.publish("a", "not connected: nothing queued"));
  Loop virtualLoop(ClockKind::Virtual);
  CHECK_THROWS_WITH_AS(MqttClient(virtualLoop, MqttOptions{}), doctest::Contains("real clock"),
                       std::invalid_argument);
}

TEST_CASE("mqtt: a client receives what it publishes to its own subscription, QoS 0 and 1") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  MqttClient client(loop, optionsFor(broker, "roundtrip"));
  Probe probe(client);
  client.subscribe("pitwall/test/#", 1);
  client.connect();
  REQUIRE(runUntil(loop, [&] { return probe.connects == 1; }));
  // the SUBACK is not reported; a message through the subscription proves it arrived
  REQUIRE(runUntil(loop, [&] {
    client.publish("pitwall/test/q0", "zero", 0);
    return probe.has("pitwall/test/q0", "zero");
  }));
  CHECK(client.publish("pitwall/test/q1", "one", 1));
  std::string big(100000, 'x');
  CHECK(client.publish("pitwall/test/big", big, 1));
  REQUIRE(runUntil(loop, [&] {
    return probe.has("pitwall/test/q1", "one") && probe.has("pitwall/test/big", big);
  }));
  CHECK_FALSE(probe.messages.back().retained);
  CHECK(probe.drops.empty());
  client.disconnect();
  REQUIRE(runUntil(loop, [&] { return !probe.drops.empty(); }));
  CHECK(probe.drops.back().first.find("on request") != std::string::npos);
  CHECK_FALSE(probe.drops.back().second);
  CHECK(client.state() == MqttClient::State::Disconnected);
}

TEST_CASE("mqtt: a retained message reaches a subscriber that comes later") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  MqttClient publisher(loop, optionsFor(broker, "publisher"));
  Probe pub(publisher);
  publisher.connect();
  REQUIRE(runUntil(loop, [&] { return pub.connects == 1; }));
  REQUIRE(publisher.publish("Anki/Host/test/S/HostStatus", "true", 1, true));
  publisher.disconnect();  // the QoS 1 PUBLISH is written before DISCONNECT
  REQUIRE(runUntil(loop, [&] { return !pub.drops.empty(); }));

  MqttClient late(loop, optionsFor(broker, "late"));
  Probe probe(late);
  late.subscribe("Anki/Host/+/S/#", 1);
  late.connect();
  REQUIRE(runUntil(loop, [&] { return probe.has("Anki/Host/test/S/HostStatus", "true"); }));
  CHECK(probe.messages.front().retained);
}

TEST_CASE("mqtt: whenDelivered waits for the broker's acknowledgements of QoS 1 messages") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  MqttClient publisher(loop, optionsFor(broker, "publisher"));
  Probe pub(publisher);
  // not connected: nothing can be waited for, done comes at once (on the loop)
  bool early = false;
  publisher.whenDelivered([&] { early = true; });
  CHECK_FALSE(early);
  REQUIRE(runUntil(loop, [&] { return early; }));

  publisher.connect();
  REQUIRE(runUntil(loop, [&] { return pub.connects == 1; }));
  constexpr int kCount = 200;
  for (int i = 0; i < kCount; ++i)
    REQUIRE(publisher.publish("pitwall/test/r" + std::to_string(i), std::to_string(i), 1, true));
  bool delivered = false;
  publisher.whenDelivered([&] {
    delivered = true;
    publisher.disconnect();  // at once: everything acknowledged is the broker's
  });
  CHECK_FALSE(delivered);  // 200 PUBACKs cannot have come back inside publish()
  REQUIRE(runUntil(loop, [&] { return delivered && !pub.drops.empty(); }));

  MqttClient late(loop, optionsFor(broker, "late"));
  Probe probe(late);
  late.subscribe("pitwall/test/#", 1);
  late.connect();
  CHECK(runUntil(loop, [&] { return probe.messages.size() == kCount; }));
  CHECK(probe.has("pitwall/test/r199", "199"));
}

TEST_CASE("mqtt: the broker publishes the last will of a client killed without disconnecting") {
  MosquittoBroker broker;
  // The client under test lives in a child process that is SIGKILLed: a real crash, the socket
  // closed by the kernel, no DISCONNECT. The child has its own loop; it touches nothing of ours.
  pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    Loop childLoop(ClockKind::Real);
    auto o = optionsFor(broker, "doomed");
    o.will = MqttWill{"pitwall/test/will", "offline", 1, true};
    MqttClient doomed(childLoop, o);
    // retained: the watcher sees it whether it subscribes before or after this
    doomed.onConnected = [&] { doomed.publish("pitwall/test/ready", "ready", 1, true); };
    doomed.connect();
    childLoop.after(std::chrono::seconds(10), [] { ::_exit(3); });
    childLoop.run();
    ::_exit(2);
  }
  Loop loop(ClockKind::Real);
  MqttClient watcher(loop, optionsFor(broker, "watcher"));
  Probe probe(watcher);
  watcher.subscribe("pitwall/test/#", 1);
  watcher.connect();
  REQUIRE(runUntil(loop, [&] { return probe.connects == 1; }));
  bool ready = runUntil(loop, [&] { return probe.has("pitwall/test/ready", "ready"); });
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  REQUIRE_MESSAGE(ready, "the child client never connected");
  CHECK_FALSE(probe.has("pitwall/test/will", "offline"));
  REQUIRE(runUntil(loop, [&] { return probe.has("pitwall/test/will", "offline"); }));
}

TEST_CASE("mqtt: a clean disconnect() does not send the last will") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  MqttClient watcher(loop, optionsFor(broker, "watcher"));
  Probe probe(watcher);
  watcher.subscribe("pitwall/test/#", 1);
  watcher.connect();
  REQUIRE(runUntil(loop, [&] { return probe.connects == 1; }));
  auto o = optionsFor(broker, "polite");
  o.will = MqttWill{"pitwall/test/will", "offline", 1, false};
  MqttClient polite(loop, o);
  Probe politeProbe(polite);
  polite.connect();
  REQUIRE(runUntil(loop, [&] { return politeProbe.connects == 1; }));
  polite.disconnect();
  REQUIRE(runUntil(loop, [&] { return !politeProbe.drops.empty(); }));
  // the broker handles the DISCONNECT before a marker sent after it on another connection
  // arrives back at the watcher; a will would have come first
  REQUIRE(watcher.publish("pitwall/test/marker", "after", 1));
  REQUIRE(runUntil(loop, [&] { return probe.has("pitwall/test/marker", "after"); }));
  CHECK_FALSE(probe.has("pitwall/test/will", "offline"));
}

TEST_CASE("mqtt: a client reconnects after a broker restart and subscribes again") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  MqttClient client(loop, optionsFor(broker, "survivor"));
  Probe probe(client);
  client.subscribe("pitwall/test/#", 1);
  client.connect();
  REQUIRE(runUntil(loop, [&] { return probe.connects == 1; }));

  broker.stop();
  REQUIRE(runUntil(loop, [&] { return !probe.drops.empty(); }));
  CHECK(probe.drops.front().first.find("lost the connection") != std::string::npos);
  CHECK(probe.drops.front().second);  // retrying
  CHECK_FALSE(client.publish("pitwall/test/x", "while down"));
  broker.start();  // same port; the broker kept nothing (persistence off, clean session)
  REQUIRE(runUntil(
      loop, [&] { return probe.connects == 2; }, std::chrono::seconds(10)));
  CHECK(client.state() == MqttClient::State::Connected);

  MqttClient other(loop, optionsFor(broker, "other"));
  Probe otherProbe(other);
  other.connect();
  REQUIRE(runUntil(loop, [&] { return otherProbe.connects == 1; }));
  // the re-sent SUBSCRIBE precedes anything the other client publishes once it is connected
  REQUIRE(other.publish("pitwall/test/after", "restart", 1));
  REQUIRE(runUntil(loop, [&] { return probe.has("pitwall/test/after", "restart"); }));
}

TEST_CASE("mqtt: an unreachable broker is reported once while the client keeps retrying") {
  int port = 0;
  {
    MosquittoBroker gone;  // a port that was free a moment ago, with nothing on it now
    port = gone.port();
  }
  Loop loop(ClockKind::Real);
  auto o = MqttOptions::fromUrl("mqtt://127.0.0.1:" + std::to_string(port));
  MqttClient client(loop, o);
  Probe probe(client);
  client.connect();
  REQUIRE(runUntil(loop, [&] { return !probe.drops.empty(); }));
  CHECK(probe.drops.front().first.find("cannot connect to the MQTT broker at mqtt://127.0.0.1:" +
                                       std::to_string(port)) != std::string::npos);
  CHECK(probe.drops.front().first.find("refused") != std::string::npos);
  CHECK(probe.drops.front().second);
  runFor(loop, std::chrono::milliseconds(1600));  // attempts at +0.5 s and +1.5 s
  CHECK(probe.drops.size() == 1);
  CHECK(client.state() != MqttClient::State::Connected);
}

TEST_CASE("mqtt: a wrong password is refused with the broker's reason and not retried") {
  BrokerOptions bo;
  bo.username = "pitwall";
  bo.password = "s3cret";
  MosquittoBroker broker(bo);
  Loop loop(ClockKind::Real);

  auto wrong = optionsFor(broker, "wrong");
  wrong.username = "pitwall";
  wrong.password = "guess";
  MqttClient refused(loop, wrong);
  Probe probe(refused);
  refused.connect();
  REQUIRE(runUntil(loop, [&] { return !probe.drops.empty(); }));
  INFO(probe.drops.front().first);
  CHECK(probe.drops.front().first.find("refused the connection") != std::string::npos);
  CHECK(probe.drops.front().first.find("not authorised") != std::string::npos);
  CHECK_FALSE(probe.drops.front().second);
  CHECK(refused.state() == MqttClient::State::Failed);
  CHECK(probe.connects == 0);

  auto right = optionsFor(broker, "right");
  right.username = "pitwall";
  right.password = "s3cret";
  MqttClient accepted(loop, right);
  Probe ok(accepted);
  accepted.connect();
  REQUIRE(runUntil(loop, [&] { return ok.connects == 1; }));
  CHECK(probe.drops.size() == 1);  // reported once, never retried
}

TEST_CASE("mqtt: TLS with a throwaway CA connects, and a server the CA did not sign is refused") {
  // ./dev test installs openssl: a machine without it fails here rather than passing untested.
  REQUIRE_MESSAGE(haveOpenssl(), "the openssl command is missing (Debian package: openssl)");
  char tmpl[] = "/tmp/pitwall-mqtt-tls-XXXXXX";
  REQUIRE(::mkdtemp(tmpl));
  std::string dir = tmpl;
  struct Cleanup {
    std::string dir;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);  // also when a REQUIRE ends the test
    }
  } cleanup{dir};
  makeCertificates(dir, "testca");
  // a second CA that signed nothing of the broker's
  REQUIRE(std::system(("cd '" + dir +
                       "' && openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1"
                       " -nodes -keyout other.key -out other.crt -days 1 -subj /CN=other"
                       " >>openssl.log 2>&1")
                          .c_str()) == 0);
  {
    BrokerOptions bo;
    bo.certFile = dir + "/server.crt";
    bo.keyFile = dir + "/server.key";
    bo.caFile = dir + "/testca.crt";
    MosquittoBroker broker(bo);
    REQUIRE(broker.url().rfind("mqtts://", 0) == 0);
    Loop loop(ClockKind::Real);

    auto good = optionsFor(broker, "tls");
    good.caFile = dir + "/testca.crt";
    MqttClient client(loop, good);
    Probe probe(client);
    client.subscribe("pitwall/tls", 1);
    client.connect();
    REQUIRE(runUntil(loop, [&] { return probe.connects == 1; }));
    REQUIRE(runUntil(loop, [&] {
      client.publish("pitwall/tls", "secret", 1);
      return probe.has("pitwall/tls", "secret");
    }));

    auto bad = optionsFor(broker, "tls-wrong-ca");
    bad.caFile = dir + "/other.crt";
    MqttClient untrusting(loop, bad);
    Probe refused(untrusting);
    untrusting.connect();
    REQUIRE(runUntil(
        loop, [&] { return !refused.drops.empty(); }, std::chrono::seconds(12)));
    INFO(refused.drops.front().first);
    CHECK(refused.drops.front().first.find("cannot connect") != std::string::npos);
    CHECK(refused.drops.front().first.find("TLS") != std::string::npos);
    CHECK(refused.drops.front().first.find("certificate verify failed") != std::string::npos);
    CHECK(refused.connects == 0);
  }
}

// The watchdog's stop of a remote car (engine/mqtt/remote.cpp): one publication on a connection
// of its own, from a thread that is not the loop's. Acknowledged by a real broker; against no
// broker at all (a refused port) false within its limit, so the watchdog's thread goes on.
TEST_CASE("mqtt: publishOnce delivers on a connection of its own, and gives up in bounded time") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  MqttClient client(loop, optionsFor(broker, "watcher"));
  Probe probe(client);
  client.subscribe("pitwall/once/#", 1);
  client.connect();
  REQUIRE(runUntil(loop, [&] { return probe.connects == 1; }));
  // until the subscription holds (its SUBACK is not reported), from the test's own thread
  REQUIRE(runUntil(loop, [&] {
    CHECK(publishOnce(optionsFor(broker, "ignored"), "pitwall/once/stop", "{\"speed\":0}", 1,
                      std::chrono::milliseconds(800)));
    return probe.has("pitwall/once/stop", "{\"speed\":0}");
  }));
  MqttOptions nowhere;
  nowhere.host = "127.0.0.1";
  nowhere.port = 1;  // nothing listens: refused
  const auto before = std::chrono::steady_clock::now();
  CHECK_FALSE(publishOnce(nowhere, "pitwall/once/stop", "{}", 1, std::chrono::milliseconds(300)));
  CHECK(std::chrono::steady_clock::now() - before < std::chrono::seconds(5));
}
