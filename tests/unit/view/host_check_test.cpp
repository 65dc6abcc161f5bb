#include "engine/view/host_check.hpp"

#include <doctest/doctest.h>

using namespace pitwall::view;

TEST_CASE("host check: a Host header's name") {
  CHECK(hostName("Example.COM:8080") == "example.com");
  CHECK(hostName("example.com.") == "example.com");
  CHECK(hostName("[::1]:80") == "::1");
  CHECK(hostName("[::1]") == "::1");
  CHECK(hostName("[::1]x").empty());    // junk after the brackets
  CHECK(hostName("[::1").empty());      // unclosed
  CHECK(hostName("::1").empty());       // IPv6 without brackets is ambiguous with a port
  CHECK(hostName("a:1:2").empty());
}

// The adversary is a page of another site whose name was rebound to 127.0.0.1: its Host and
// Origin agree with each other, but the name is not one the view answers to.
TEST_CASE("host check: loopback, the machine's names and --view-host are served; a rebound "
          "name and a foreign Origin are refused with a sentence") {
  HostCheck hosts;
  hosts.start("127.0.0.1", {"race.example.org"});
  CHECK_FALSE(hosts.refusal("127.0.0.1:8080", std::nullopt));
  CHECK_FALSE(hosts.refusal("localhost:8080", "http://localhost:8080"));
  CHECK_FALSE(hosts.refusal("[::1]:8080", std::nullopt));
  CHECK_FALSE(hosts.refusal("race.example.org", "https://race.example.org"));
  CHECK(hosts.proxied("race.example.org"));
  CHECK_FALSE(hosts.proxied("localhost"));

  auto rebound = hosts.refusal("attacker.example:8080", "http://attacker.example:8080");
  REQUIRE(rebound);
  CHECK(rebound->find("does not serve the name 'attacker.example:8080'") != std::string::npos);
  CHECK(rebound->find("--view-host") != std::string::npos);

  auto foreign = hosts.refusal("127.0.0.1:8080", "http://evil.example");
  REQUIRE(foreign);
  CHECK(foreign->find("not for http://evil.example") != std::string::npos);

  auto none = hosts.refusal(std::nullopt, std::nullopt);
  REQUIRE(none);
  CHECK(none->find("without a Host header") != std::string::npos);

  // a huge header is named in part, not copied whole into the answer
  auto huge = hosts.refusal(std::string(100000, 'a'), std::nullopt);
  REQUIRE(huge);
  CHECK(huge->size() < 400);
}
