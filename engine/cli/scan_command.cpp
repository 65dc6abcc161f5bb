// pitwall scan: the Anki cars in Bluetooth range, as a table or as JSON lines.
#include <boost/asio/signal_set.hpp>
#include <csignal>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/core/log.hpp"
#include "engine/fleet/ble_central.hpp"

namespace pitwall::cli {

namespace {

struct Row {
  std::string address, adapter, name, model;
  int modelId = -1;
  std::uint32_t identifier = 0;
  std::optional<int> firmware, rssi;
  std::string battery;  // full, low, charging, ok; "?" when BlueZ hid the local name's state byte
};

Row rowOf(const ble::Sighting& s) {
  const ble::Device& d = s.device;
  Row r;
  r.address = s.address;
  for (const auto& [adapter, path] : s.paths)
    r.adapter += (r.adapter.empty() ? "" : ",") + adapter.substr(adapter.rfind('/') + 1);
  auto local = d.localName();
  r.name = local.user_name;
  if (d.manufacturer) {
    r.modelId = d.manufacturer->model_id;
    r.model = anki::modelName(d.manufacturer->model_id);
    r.identifier = d.manufacturer->identifier;
  }
  if (d.stateKnown()) {
    if (local.version) r.firmware = local.version;
    r.battery = local.on_charger     ? "charging"
                : local.low_battery  ? "low"
                : local.full_battery ? "full"
                                     : "ok";
  } else {
    r.battery = "?";
  }
  r.rssi = d.rssi;
  return r;
}

std::string hex(int v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", v);
  return buf;
}

void printTable(const std::vector<Row>& rows) {
  std::vector<std::array<std::string, 7>> cells;
  cells.push_back({"ADDRESS", "NAME", "MODEL", "FIRMWARE", "BATTERY", "RSSI", "ADAPTER"});
  for (const auto& r : rows)
    cells.push_back({r.address, r.name.empty() ? "-" : r.name, r.model.empty() ? "-" : r.model,
                     r.firmware ? hex(*r.firmware) : "?", r.battery,
                     r.rssi ? std::to_string(*r.rssi) + " dBm" : "?", r.adapter});
  std::array<std::size_t, 7> width{};
  for (const auto& row : cells)
    for (std::size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
  for (const auto& row : cells) {
    std::string line;
    for (std::size_t i = 0; i < row.size(); ++i) {
      line += row[i];
      if (i + 1 < row.size()) line += std::string(width[i] - row[i].size() + 2, ' ');
    }
    std::cout << line << "\n";
  }
}

void printJson(const std::vector<Row>& rows) {
  for (const auto& r : rows) {
    nlohmann::json j;
    j["address"] = r.address;
    j["name"] = r.name;
    j["model"] = r.model.empty() ? nlohmann::json() : nlohmann::json(r.model);
    j["modelId"] = r.modelId < 0 ? nlohmann::json() : nlohmann::json(r.modelId);
    j["identifier"] = r.identifier;
    j["firmware"] = r.firmware ? nlohmann::json(*r.firmware) : nlohmann::json();
    j["battery"] = r.battery == "?" ? nlohmann::json() : nlohmann::json(r.battery);
    j["rssi"] = r.rssi ? nlohmann::json(*r.rssi) : nlohmann::json();
    j["adapter"] = r.adapter;
    std::cout << j.dump() << "\n";
  }
}

}  // namespace

int scan(const ScanOptions& options) {
  Loop loop(ClockKind::Real);
  std::unique_ptr<ble::Bluez> bluez;
  try {
    bluez = std::make_unique<ble::Bluez>(loop);
  } catch (const ble::BleError& e) {
    return fail("scan", e.what());
  }
  int status = 0;
  std::vector<ble::Sighting> found;
  auto failed = [&](const std::string& why) {
    status = fail("scan", why);
    loop.stop();
  };
  bluez->start([&](std::optional<std::string> error) {
    if (error) return failed(*error);
    std::vector<const ble::Adapter*> adapters;
    try {
      adapters = bluez->pickAdapters(options.adapters);
    } catch (const ble::BleError& e) {
      return failed(e.what());
    }
    ble::scanForCars(*bluez, adapters, fromSeconds(options.timeout), {},
                     [&](std::optional<std::string> error, std::vector<ble::Sighting> cars) {
                       if (error) return failed(*error);
                       found = std::move(cars);
                       // Let StopDiscovery reach BlueZ before leaving.
                       loop.after(std::chrono::milliseconds(50), [&] { loop.stop(); });
                     });
  });
  boost::asio::signal_set signals(loop.io(), SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code& ec, int) {
    if (!ec) {
      status = 130;
      loop.stop();
    }
  });
  loop.run();
  signals.cancel();
  if (status != 0) return status;

  std::vector<Row> rows;
  for (const auto& s : found) rows.push_back(rowOf(s));
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    return a.rssi.value_or(-1000) > b.rssi.value_or(-1000);
  });
  if (options.json) {
    printJson(rows);
  } else if (rows.empty()) {
    std::cout << "no Anki cars found in " << options.timeout
              << " s: are they switched on, charged, and not connected to a phone?\n";
  } else {
    printTable(rows);
  }
  return 0;
}

Command addScanCommand(CLI::App& app) {
  auto scan = std::make_shared<ScanOptions>();
  auto* cmd = app.add_subcommand("scan", "List the Anki cars in Bluetooth range");
  cmd->add_option("--timeout", scan->timeout, "Seconds to listen (default 5)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", scan->json, "JSON lines instead of a table");
  cmd->add_option("--adapter", scan->adapters, "Use this controller, hci0, … (repeatable)");
  return {cmd, [scan] { return cli::scan(*scan); }};
}

}  // namespace pitwall::cli
