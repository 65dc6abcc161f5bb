// The join code (docs/view.md "Pairing"): six digits from the kernel's CSPRNG, and a guesser
// locked out per address — five wrong codes, then a lock-out that doubles with each further one.
#include "engine/view/pairing.hpp"

#include <doctest/doctest.h>

#include <set>

using namespace pitwall;
using view::Pairing;

TEST_CASE("pairing: a join code is six digits, and codes differ") {
  std::set<std::string> seen;
  for (int i = 0; i < 200; ++i) {
    std::string code = Pairing::newCode();
    CHECK(code.size() == 6);
    CHECK(code.find_first_not_of("0123456789") == std::string::npos);
    seen.insert(code);
  }
  CHECK(seen.size() > 190);  // 200 draws from 10^6: a repeat or two at most
  CHECK(Pairing(true, "").code().size() == 6);
  CHECK(Pairing(false, "").code().empty());
}

TEST_CASE("pairing: no code needed, any is taken; the right code is taken") {
  Pairing open(false, "");
  CHECK(open.check("10.0.0.2", "", 0));
  Pairing p(true, "123456");
  CHECK(p.check("10.0.0.2", "123456", 0));
  CHECK_FALSE(p.check("10.0.0.2", "12345", 0));
  CHECK_FALSE(p.check("10.0.0.2", "1234567", 0));
  CHECK_FALSE(p.check("10.0.0.2", "", 0));
}

TEST_CASE("pairing: five wrong codes lock the address out, longer with each further one") {
  Pairing p(true, "123456");
  for (int i = 1; i < Pairing::kFreeTries; ++i) {
    auto r = p.check("10.0.0.2", "000000", i);
    REQUIRE_FALSE(r);
    CHECK(r.error().find("left before a lock-out") != std::string::npos);
  }
  auto fifth = p.check("10.0.0.2", "000000", 10);
  REQUIRE_FALSE(fifth);
  CHECK(fifth.error().find("no more tries from 10.0.0.2 for 30 seconds") != std::string::npos);
  // during the lock-out even the right code is refused; another address is not held back
  auto locked = p.check("10.0.0.2", "123456", 20);
  REQUIRE_FALSE(locked);
  CHECK(locked.error().find("try again in 20 seconds") != std::string::npos);
  CHECK(p.check("10.0.0.3", "123456", 20));
  // after it, one more wrong code locks for twice as long
  auto sixth = p.check("10.0.0.2", "000001", 41);
  REQUIRE_FALSE(sixth);
  CHECK(sixth.error().find("for 60 seconds") != std::string::npos);
  CHECK(p.check("10.0.0.2", "123456", 102));
  // a guesser at its limit needs ~10^6 / 5 lock-outs: capped at an hour each, years
  Pairing q(true, "123456");
  double t = 0;
  for (int i = 0; i < 40; ++i) {
    auto r = q.check("10.0.0.9", "000000", t);
    (void)r;
    t += Pairing::kMaxLockout + 1;
  }
  auto last = q.check("10.0.0.9", "000000", t);
  REQUIRE_FALSE(last);
  CHECK(last.error().find("for 3600 seconds") != std::string::npos);
}

TEST_CASE("pairing: an IPv6 client is counted by its /64 (a host has a whole /64)") {
  CHECK(Pairing::clientKey("2001:db8:1:2:aaaa::1") == "2001:db8:1:2::/64");
  CHECK(Pairing::clientKey("2001:db8:1:2:bbbb::7") == "2001:db8:1:2::/64");
  CHECK(Pairing::clientKey("::ffff:192.168.1.9") == "192.168.1.9");
  CHECK(Pairing::clientKey("192.168.1.9") == "192.168.1.9");
  Pairing p(true, "123456");
  for (int i = 0; i < Pairing::kFreeTries; ++i)
    (void)p.check(Pairing::clientKey("2001:db8:1:2::" + std::to_string(i + 1)), "000000", 1);
  CHECK_FALSE(p.check(Pairing::clientKey("2001:db8:1:2::99"), "123456", 2));
}

TEST_CASE("pairing: the table of guessers is bounded") {
  Pairing p(true, "123456");
  for (std::size_t i = 0; i < Pairing::kMaxClients; ++i)
    for (int k = 0; k < Pairing::kFreeTries; ++k)
      (void)p.check("c" + std::to_string(i), "000000", 1);
  // full of locked-out guessers: a new one is refused with a sentence, not remembered
  auto r = p.check("new", "000000", 2);
  REQUIRE_FALSE(r);
  CHECK(r.error().find("too many clients are guessing") != std::string::npos);
  // the right code still pairs
  CHECK(p.check("new", "123456", 2));
  // their lock-outs over (30 s) but not an hour gone: still remembered, so cycling through more
  // addresses than the table holds never starts a count afresh
  auto soon = p.check("new", "000000", 1000);
  REQUIRE_FALSE(soon);
  CHECK(soon.error().find("too many clients are guessing") != std::string::npos);
  CHECK_FALSE(p.check("c0", "000000", 1000).error().find("tries left") != std::string::npos);
  // an hour without a wrong code from them: forgotten, and the newcomer is counted
  auto later = p.check("new", "000000", 1 + Pairing::kMaxLockout + 1);
  REQUIRE_FALSE(later);
  CHECK(later.error().find("4 tries left") != std::string::npos);
}
