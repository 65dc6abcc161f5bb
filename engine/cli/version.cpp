#include "engine/cli/version.hpp"

#include <mosquitto.h>
#include <lua.hpp>

#include <array>
#include <boost/version.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "engine/cli/build_info.hpp"
#include "engine/core/data_dir.hpp"

namespace pitwall::cli {

namespace {

// The BlueZ on this machine: bluetoothd's own --version, or why there is none. BlueZ has no
// version on D-Bus, so this is what `--ble` would talk to only when the daemon is this one.
std::string bluezVersion() {
  for (const char* daemon : {"/usr/libexec/bluetooth/bluetoothd", "/usr/lib/bluetooth/bluetoothd",
                             "/usr/sbin/bluetoothd"}) {
    std::error_code ec;
    if (!std::filesystem::exists(daemon, ec)) continue;
    std::unique_ptr<FILE, int (*)(FILE*)> p(
        ::popen((std::string(daemon) + " --version 2>/dev/null").c_str(), "r"), ::pclose);
    std::array<char, 64> line{};
    if (p && std::fgets(line.data(), line.size(), p.get())) {
      std::string v(line.data());
      while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
      if (!v.empty()) return "BlueZ " + v + " (" + daemon + ")";
    }
  }
  return "BlueZ: bluetoothd is not installed (--ble needs it: apt install bluez)";
}

}  // namespace

std::string versionText() {
  std::string text = std::string("pitwall ") + build::version;
  if (*build::gitDescribe) text += std::string(" (git ") + build::gitDescribe + ")";
  int major = 0, minor = 0, revision = 0;
  mosquitto_lib_version(&major, &minor, &revision);
  const int boost = BOOST_VERSION;
  text += std::string("\n") + LUA_RELEASE + ", sdbus-c++ " + build::sdbusVersion +
          ", libmosquitto " + std::to_string(major) + "." + std::to_string(minor) + "." +
          std::to_string(revision) + ", Boost " + std::to_string(boost / 100000) + "." +
          std::to_string(boost / 100 % 1000) + "." + std::to_string(boost % 100);
  text += "\n" + bluezVersion();
  auto data = dataDir();
  text += "\ndata: " + (data ? data->string() : std::string("not found (") + data.error() + ")");
  return text;
}

}  // namespace pitwall::cli
