#include "tests/support/mosquitto_broker.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace pitwall::testing {

namespace {

const char* mosquittoPath() {
  return ::access("/usr/sbin/mosquitto", X_OK) == 0 ? "/usr/sbin/mosquitto" : nullptr;
}

int freeLoopbackPort() {
  int s = ::socket(AF_INET, SOCK_STREAM, 0);
  if (s < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  if (::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(s);
    throw std::runtime_error(std::string("cannot find a free port: ") + std::strerror(errno));
  }
  ::close(s);
  return ntohs(a.sin_port);
}

bool accepts(int port) {
  int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<uint16_t>(port));
  bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(s);
  return ok;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

bool MosquittoBroker::available() {
  return mosquittoPath() != nullptr;
}

MosquittoBroker::MosquittoBroker(BrokerOptions options) : options_(std::move(options)) {
  if (!available())
    throw std::runtime_error("mosquitto is not installed (Debian package: mosquitto)");
  char tmpl[] = "/tmp/pitwall-mosquitto-XXXXXX";
  if (!::mkdtemp(tmpl)) throw std::runtime_error(std::string("mkdtemp: ") + std::strerror(errno));
  dir_ = tmpl;
  port_ = freeLoopbackPort();
  std::ofstream conf(dir_ + "/mosquitto.conf");
  conf << "listener " << port_ << " 127.0.0.1\n"
       << "persistence false\n"
       << (options_.tcpNoDelay ? "set_tcp_nodelay true\n" : "") << "log_dest stderr\n"
       << "log_type error\nlog_type warning\nlog_type notice\n"
       << "user root\n";  // run as root (a container): stay root, keep reading the temp dir
  if (!options_.username.empty()) {
    std::string cmd = "mosquitto_passwd -c -b '" + dir_ + "/passwd' '" + options_.username + "' '" +
                      options_.password + "' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) != 0)
      throw std::runtime_error("mosquitto_passwd failed (Debian package: mosquitto)");
    conf << "allow_anonymous false\npassword_file " << dir_ << "/passwd\n";
  } else {
    conf << "allow_anonymous true\n";
  }
  if (!options_.certFile.empty())
    conf << "certfile " << options_.certFile << "\nkeyfile " << options_.keyFile << "\ncafile "
         << options_.caFile << "\n";
  conf.close();
  start();
}

MosquittoBroker::~MosquittoBroker() {
  stop();
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

std::string MosquittoBroker::url() const {
  return std::string(options_.certFile.empty() ? "mqtt://" : "mqtts://") +
         "127.0.0.1:" + std::to_string(port_);
}

void MosquittoBroker::start() {
  if (pid_ > 0) return;
  std::string conf = dir_ + "/mosquitto.conf", log = dir_ + "/mosquitto.log";
  pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    FILE* out = std::freopen(log.c_str(), "a", stderr);
    if (out) ::dup2(::fileno(stderr), STDOUT_FILENO);
    ::execl(mosquittoPath(), "mosquitto", "-c", conf.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  pid_ = pid;
  // Started when it accepts a connection; bounded, and a broker that died says why.
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!accepts(port_)) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("mosquitto exited at start: " + slurp(log));
    }
    if (std::chrono::steady_clock::now() > deadline) {
      stop();
      throw std::runtime_error("mosquitto did not listen on port " + std::to_string(port_) +
                               " within 5 s: " + slurp(log));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void MosquittoBroker::stop() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
}

}  // namespace pitwall::testing
