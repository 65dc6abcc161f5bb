#pragma once
// Which names the race view answers to (docs/view.md "Pairing"), its defence against DNS
// rebinding: a page of another site whose name now resolves to this machine sends its own name
// as Host (and Origin), and is refused. The view serves loopback names and addresses, this
// machine's addresses (read again, at most every few seconds, when a Host gives one it does not
// know: DHCP, a hotspot turned on), its host name (and NAME.local), the address it is bound to,
// and the names given with --view-host (a reverse proxy's, whose requests may carry
// X-Forwarded-For).
#include <boost/asio/ip/address.hpp>
#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace pitwall::view {

// The name in a Host header: lower case, without the port or a final dot; an IPv6 address
// without its brackets. Empty when malformed.
std::string hostName(std::string_view host);
// This machine's addresses (getifaddrs), as text without an IPv6 zone.
std::set<std::string> machineAddresses();
// A loopback address (127.0.0.0/8, ::1, or a v4-mapped 127.x).
bool loopback(const boost::asio::ip::address& a);

class HostCheck {
 public:
  // `bound`: the address the view listens on; `proxies`: the --view-host names.
  void start(const std::string& bound, const std::vector<std::string>& proxies);
  // Whether a Host's name (hostName) is one the view answers to.
  bool serves(const std::string& name);
  // Whether requests for it come through a reverse proxy (--view-host).
  bool proxied(const std::string& name) const { return proxies_.contains(name); }
  // Why a request with this Host header (none: absent) and Origin header is refused, a sentence
  // for the browser; nothing when it is answered.
  std::optional<std::string> refusal(std::optional<std::string_view> host,
                                     std::optional<std::string_view> origin);

 private:
  std::set<std::string> names_;      // the names a Host may give (with the machine's)
  std::set<std::string> proxies_;    // --view-host: requests for these may be forwarded
  std::set<std::string> addresses_;  // this machine's, read again when a Host is not among them
  std::chrono::steady_clock::time_point addressesRead_{};
};

}  // namespace pitwall::view
