#pragma once
// A private mosquitto broker for one test: its own temp dir and config, a free loopback port
// (found by binding port 0), started as a child process and stopped (SIGTERM, reaped) when the
// object goes away. Never a system broker.
#include <sys/types.h>

#include <string>

namespace pitwall::testing {

struct BrokerOptions {
  // username → password; non-empty: anonymous clients are refused (mosquitto_passwd -b)
  std::string username, password;
  // TLS listener with these PEM files (a test makes them; see mqtt_client_test.cpp)
  std::string certFile, keyFile, caFile;
  // set_tcp_nodelay, as docs/mqtt.md recommends for a broker (the benchmark compares)
  bool tcpNoDelay = true;
};

class MosquittoBroker {
 public:
  // Throws std::runtime_error when mosquitto is missing or does not start listening.
  explicit MosquittoBroker(BrokerOptions options = {});
  ~MosquittoBroker();
  MosquittoBroker(const MosquittoBroker&) = delete;
  MosquittoBroker& operator=(const MosquittoBroker&) = delete;

  int port() const { return port_; }
  std::string url() const;  // mqtt://127.0.0.1:PORT, or mqtts:// with TLS
  const std::string& dir() const { return dir_; }

  void stop();   // SIGTERM, waits for it to exit
  void start();  // again, on the same port (a restarted broker)
  bool running() const { return pid_ > 0; }

  static bool available();  // mosquitto is installed

 private:
  BrokerOptions options_;
  std::string dir_;
  int port_ = 0;
  pid_t pid_ = -1;
};

}  // namespace pitwall::testing
