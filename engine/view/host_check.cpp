#include "engine/view/host_check.hpp"

#include <ifaddrs.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>

namespace pitwall::view {

namespace asio = boost::asio;

namespace {

constexpr auto kAddressesFresh = std::chrono::seconds(5);  // this machine's addresses, read again

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string machineName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return {};
  return lower(name);
}

}  // namespace

std::string hostName(std::string_view host) {
  std::string_view name;
  if (!host.empty() && host.front() == '[') {
    auto close = host.find(']');
    if (close == std::string_view::npos) return {};
    std::string_view rest = host.substr(close + 1);
    if (!rest.empty() && rest.front() != ':') return {};
    name = host.substr(1, close - 1);
  } else {
    auto colon = host.find(':');
    if (colon != std::string_view::npos && host.find(':', colon + 1) != std::string_view::npos)
      return {};
    name = host.substr(0, colon);
  }
  std::string out = lower(name);
  if (!out.empty() && out.back() == '.') out.pop_back();
  return out;
}

std::set<std::string> machineAddresses() {
  std::set<std::string> out;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return out;
  for (ifaddrs* i = list; i; i = i->ifa_next) {
    if (!i->ifa_addr) continue;
    if (i->ifa_addr->sa_family == AF_INET) {
      const auto* in = reinterpret_cast<const sockaddr_in*>(i->ifa_addr);
      out.insert(asio::ip::address_v4(ntohl(in->sin_addr.s_addr)).to_string());
    } else if (i->ifa_addr->sa_family == AF_INET6) {
      const auto* in6 = reinterpret_cast<const sockaddr_in6*>(i->ifa_addr);
      asio::ip::address_v6::bytes_type bytes;
      std::copy(std::begin(in6->sin6_addr.s6_addr), std::end(in6->sin6_addr.s6_addr),
                bytes.begin());
      out.insert(asio::ip::address_v6(bytes).to_string());
    }
  }
  ::freeifaddrs(list);
  return out;
}

bool loopback(const asio::ip::address& a) {
  if (a.is_v6() && a.to_v6().is_v4_mapped())
    return asio::ip::make_address_v4(asio::ip::v4_mapped, a.to_v6()).is_loopback();
  return a.is_loopback();
}

void HostCheck::start(const std::string& bound, const std::vector<std::string>& proxies) {
  for (const auto& n : proxies) {
    names_.insert(hostName(n));
    proxies_.insert(hostName(n));
  }
  if (std::string name = machineName(); !name.empty()) {
    names_.insert(name);
    if (name.find('.') == std::string::npos) names_.insert(name + ".local");  // mDNS
  }
  names_.insert(bound);
  addresses_ = machineAddresses();
  addressesRead_ = std::chrono::steady_clock::now();
}

bool HostCheck::serves(const std::string& name) {
  if (name == "localhost" || name.ends_with(".localhost")) return true;  // RFC 6761: loopback
  if (names_.contains(name)) return true;
  boost::system::error_code ec;
  auto a = asio::ip::make_address(name, ec);
  if (ec) return false;
  if (loopback(a)) return true;
  const std::string text = a.to_string();
  if (addresses_.contains(text)) return true;
  // a new address (DHCP, a hotspot turned on): read them again, at most every few seconds
  auto now = std::chrono::steady_clock::now();
  if (now - addressesRead_ < kAddressesFresh) return false;
  addressesRead_ = now;
  addresses_ = machineAddresses();
  return addresses_.contains(text);
}

std::optional<std::string> HostCheck::refusal(std::optional<std::string_view> host,
                                              std::optional<std::string_view> origin) {
  if (!host) return "a request without a Host header (the race view answers HTTP/1.1 with Host)";
  const std::string name = hostName(*host);
  if (name.empty() || !serves(name))
    return "the race view does not serve the name '" + std::string(host->substr(0, 100)) +
           "': open it by this machine's address or name (or give --view-host NAME for a "
           "reverse proxy's)";
  if (origin) {
    const std::string o = lower(*origin);
    const std::string h = lower(*host);
    if (o != "http://" + h && o != "https://" + h)
      return "the race view is for its own page, not for " + std::string(origin->substr(0, 200));
  }
  return std::nullopt;
}

}  // namespace pitwall::view
