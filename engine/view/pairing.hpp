#pragma once
// Who may drive through the race view (docs/view.md "Pairing"): on any address but loopback (or
// behind --view-host), a page takes a seat, drives or controls a replay only with the join code
// that the terminal prints and the race view shows. Wrong codes are counted per client address
// (an IPv6 client by its /64: one host has a whole /64) and locked out: kFreeTries wrong codes,
// then kFirstLockout seconds, doubled with each further wrong code (up to kMaxLockout), so the
// 10^6 codes cannot be tried. The table of clients is bounded (kMaxClients).
#include <cstddef>
#include <map>
#include <string>
#include <string_view>

#include "engine/core/result.hpp"

namespace pitwall::view {

class Pairing {
 public:
  static constexpr int kFreeTries = 5;
  static constexpr double kFirstLockout = 30;  // s
  static constexpr double kMaxLockout = 3600;  // s
  static constexpr std::size_t kMaxClients = 4096;
  static constexpr std::size_t kCodeDigits = 6;

  // `required`: whether a code is needed at all; `code`: empty for a new one (newCode()).
  Pairing(bool required, std::string code);

  // kCodeDigits decimal digits from the kernel's CSPRNG (getrandom), uniform.
  static std::string newCode();
  // The key a client's attempts are counted by: the address, an IPv6 one cut to its /64.
  static std::string clientKey(std::string_view address);

  bool required() const { return required_; }
  const std::string& code() const { return code_; }

  // A code given by `client` (clientKey()) at `now` (seconds, any steady origin): true when it is
  // the join code; else the sentence to show (wrong, or locked out and for how long).
  Result<bool, std::string> check(const std::string& client, std::string_view given, double now);

 private:
  struct Tries {
    int wrong = 0;
    double lockedUntil = 0;
    double last = 0;
  };
  bool required_;
  std::string code_;
  std::map<std::string, Tries> tries_;
};

}  // namespace pitwall::view
