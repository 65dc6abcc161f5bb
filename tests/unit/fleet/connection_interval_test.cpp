#include "engine/fleet/connection_interval.hpp"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdlib>

#include <cstdio>
#include <fstream>
#include <string>

using namespace pitwall::ble;

namespace {
// A main.conf with `text`, removed when the test case ends.
struct Conf {
  std::string path;
  explicit Conf(const std::string& text) {
    char name[] = "/tmp/pitwall-main-conf-XXXXXX";
    int fd = mkstemp(name);
    REQUIRE(fd >= 0);
    close(fd);
    path = name;
    std::ofstream(path, std::ios::binary) << text;
  }
  ~Conf() { std::remove(path.c_str()); }
};
}  // namespace

TEST_CASE("connection interval: the kernel's default unless main.conf's [LE] sets one") {
  LeInterval none = leInterval("/nonexistent/main.conf");
  CHECK(none.minMs == 30);
  CHECK(none.maxMs == 50);
  CHECK_FALSE(none.fromConfig);
  CHECK(carsSuited(none) == 13);  // 50 ms / 3.75 ms a car

  Conf debian("[General]\n#Name = BlueZ\n\n[LE]\n#MinConnectionInterval=7\n");
  CHECK_FALSE(leInterval(debian.path).fromConfig);  // Debian's file: every key commented out

  Conf fast(
      "[General]\nName = pit\n[LE]\nMinConnectionInterval=6\nMaxConnectionInterval=12\n"
      "ConnectionLatency=0\n");
  LeInterval f = leInterval(fast.path);
  CHECK(f.fromConfig);
  CHECK(f.minMs == doctest::Approx(7.5));
  CHECK(f.maxMs == doctest::Approx(15));
  CHECK(carsSuited(f) == 4);
}

TEST_CASE("connection interval: what bluetoothd would refuse is the kernel's default") {
  for (const char* text :
       {"[LE]\nMinConnectionInterval=5\nMaxConnectionInterval=12\n",            // under 7.5 ms
        "[LE]\nMaxConnectionInterval=3201\n",                                   // over 4 s
        "[LE]\nMinConnectionInterval=40\nMaxConnectionInterval=24\n",           // min over max
        "[LE]\nMaxConnectionInterval=abc\n",                                    // not a number
        "[LE]\nMaxConnectionInterval=99999999999999999999999\n",                // beyond an int
        "[LE\nMaxConnectionInterval=12\n",                                      // not INI
        "\xff\xfe\x00garbage\x01\x02=\x03\n[LE]\nMaxConnectionInterval=12"}) {  // binary
    CAPTURE(text);
    Conf c(text);
    LeInterval l = leInterval(c.path);
    if (l.fromConfig) {
      CHECK(l.maxMs == doctest::Approx(15));  // only the binary file's [LE] may be read
    } else {
      CHECK(l.maxMs == 50);
    }
  }
  Conf huge(std::string(4 << 20, 'x'));  // 4 MiB of one line
  CHECK_FALSE(leInterval(huge.path).fromConfig);
}

TEST_CASE("connection interval: the sentence says what is asked, and what to do when too short") {
  bool suits = false;
  std::string ok = intervalSentence("hci0", 6, LeInterval{}, suits);
  CHECK(suits);
  CHECK(ok ==
        "hci0: 6 cars; BlueZ asks each for a 30–50 ms connection interval (the kernel's "
        "default; what the controller grants is not told), which suits up to 13 cars");
  std::string tight = intervalSentence("hci1", 5, LeInterval{7.5, 15, true}, suits);
  CHECK_FALSE(suits);
  CHECK(tight.find("7.5–15 ms") != std::string::npos);
  CHECK(tight.find("main.conf's [LE]") != std::string::npos);
  CHECK(tight.find("too short for 5 cars") != std::string::npos);
  CHECK(tight.find("MaxConnectionInterval in /etc/bluetooth/main.conf to 15 or more") !=
        std::string::npos);
  CHECK(tight.find("--adapter") != std::string::npos);
}
