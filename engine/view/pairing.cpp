#include "engine/view/pairing.hpp"

#include <sys/random.h>

#include <algorithm>
#include <boost/asio/ip/address.hpp>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace pitwall::view {

namespace {

std::uint32_t randomWord() {
  std::uint32_t v = 0;
  auto* p = reinterpret_cast<unsigned char*>(&v);
  std::size_t got = 0;
  while (got < sizeof v) {
    ssize_t n = ::getrandom(p + got, sizeof v - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("the kernel gave no random bytes for the join code (getrandom)");
    }
    got += static_cast<std::size_t>(n);
  }
  return v;
}

// Equal without an early exit (the time to refuse says nothing of how much was right).
bool same(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::string seconds(double s) {
  const long whole = static_cast<long>(std::ceil(s));
  return std::to_string(whole) + (whole == 1 ? " second" : " seconds");
}

}  // namespace

Pairing::Pairing(bool required, std::string code)
    : required_(required), code_(code.empty() && required ? newCode() : std::move(code)) {}

std::string Pairing::newCode() {
  constexpr std::uint32_t kRange = 1'000'000;  // 10^kCodeDigits
  // rejection sampling: no digit is likelier than another
  const std::uint32_t limit = UINT32_MAX - UINT32_MAX % kRange;
  std::uint32_t v;
  do v = randomWord();
  while (v >= limit);
  std::string code = std::to_string(v % kRange);
  return std::string(kCodeDigits - code.size(), '0') + code;
}

std::string Pairing::clientKey(std::string_view address) {
  boost::system::error_code ec;
  auto a = boost::asio::ip::make_address(std::string(address), ec);
  if (ec || !a.is_v6()) return std::string(address);
  auto v6 = a.to_v6();
  if (v6.is_v4_mapped())
    return boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, v6).to_string();
  auto bytes = v6.to_bytes();
  std::fill(bytes.begin() + 8, bytes.end(), 0);
  return boost::asio::ip::address_v6(bytes).to_string() + "/64";
}

Result<bool, std::string> Pairing::check(const std::string& client, std::string_view given,
                                         double now) {
  if (!required_) return true;
  auto it = tries_.find(client);
  if (it != tries_.end() && now < it->second.lockedUntil)
    return Unexpected{"too many wrong join codes from " + client + ": try again in " +
                      seconds(it->second.lockedUntil - now) +
                      " (the code is on the race view and in the terminal that started the run)"};
  if (same(given, code_)) {
    if (it != tries_.end()) tries_.erase(it);
    return true;
  }
  if (it == tries_.end()) {
    if (tries_.size() >= kMaxClients) {
      // forget only a client silent for the longest lock-out: forgetting one whose lock-out is
      // merely over (or that has a try or two left) would start its count again, and an attacker
      // cycling through more addresses than the table holds would never be locked out. None:
      // every unknown client is refused until one is (the right code still pairs, above)
      std::erase_if(tries_, [now](const auto& e) { return e.second.last + kMaxLockout <= now; });
      if (tries_.size() >= kMaxClients)
        return Unexpected{"too many clients are guessing the join code: try again in a minute"};
    }
    it = tries_.emplace(client, Tries{}).first;
  }
  Tries& t = it->second;
  t.wrong++;
  t.last = now;
  if (t.wrong >= kFreeTries) {
    const double lock = std::min(kMaxLockout, kFirstLockout * std::pow(2.0, t.wrong - kFreeTries));
    t.lockedUntil = now + lock;
    return Unexpected{"wrong join code '" + std::string(given.substr(0, 16)) + "' (" +
                      std::to_string(t.wrong) + " wrong in a row): no more tries from " + client +
                      " for " + seconds(lock) +
                      " (the code is on the race view and in the terminal that started the run)"};
  }
  const int left = kFreeTries - t.wrong;
  return Unexpected{"wrong join code '" + std::string(given.substr(0, 16)) +
                    "': " + std::to_string(left) + (left == 1 ? " try" : " tries") +
                    " left before a lock-out (the code is on the race view and in the terminal "
                    "that started the run)"};
}

}  // namespace pitwall::view
