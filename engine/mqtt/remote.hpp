#pragma once
// Remote cars (docs/mqtt.md "Remote cars"): the cars that bridges on other hosts publish, put in
// the local fleet as ordinary AnkiCars. Each has a RemoteLink:
//
//  - up while its bridge has it (its host's S/Cars lists it, or before any S/Cars named it, its
//    S/CarStatus says online) and its host's S/HostStatus (when known) says true; down, with the
//    reason, when either turns false or this client loses the broker;
//  - its kind comes from its S/Information: a pitwall bridge's says "bridge":"pitwall" and its
//    host. Its frames are then the bridge's Anki/Car/<car>/E/frame events, fed to
//    AnkiCar::receive, so the car's state and its Lua events are exactly those of a local car.
//    Any other car is the seed's controller's, which has no E/frame: its
//    E/Messages/ANKI_VEHICLE_MSG_V2C_… events are turned back into the messages they were made
//    from (topics::readMessageEvent). Each kind reads one stream only, so no event comes twice;
//  - a command becomes an intent on Anki/Car/<car>/I (topics::intentPayload, the controller's
//    form where it has one), QoS 1, which the owning bridge validates again and executes.
//    sdk-mode is the bridge's business (it keeps its cars in SDK mode) and is accepted without
//    sending anything.
//
// Hostile publications on the tree (docs/mqtt.md "Hostile input") are ignored with a warning:
// a payload beyond the limits is refused before it is parsed, an exception from any message is
// caught, and the warnings themselves are limited (10 a second, 20 at once; the rest counted).
//
// start() subscribes, then publishes a marker to a topic of its own: the broker delivers it after
// every retained message of the earlier subscriptions, so when it comes back the cars online at
// that moment are all known.
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "engine/core/emergency_stops.hpp"
#include "engine/core/token_bucket.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/mqtt/topics.hpp"
#include "engine/transport/mqtt_client.hpp"

namespace pitwall {

class RemoteLink;

class RemoteCars {
 public:
  // The client must not be connected yet (its handlers are set here). The loop, the fleet and
  // the client outlive this object.
  RemoteCars(Loop& loop, Fleet& fleet, MqttClient& client, topics::PayloadLimits limits = {});
  // A spectator (pitwall view --mqtt): nothing is ever published — no sync marker (synced()
  // comes with the connection; the retained state follows as it arrives) and no command: a
  // car's command is refused unsent. Set before start().
  void setReadOnly(bool readOnly) { readOnly_ = readOnly; }
  bool readOnly() const { return readOnly_; }
  ~RemoteCars();
  RemoteCars(const RemoteCars&) = delete;
  RemoteCars& operator=(const RemoteCars&) = delete;

  // Connects; synced() once the broker has delivered the retained state, or failed(reason) when
  // the broker refuses this client.
  void start(std::function<void()> synced, std::function<void(const std::string&)> failed);

  // Remote cars online now.
  std::size_t onlineCount() const;
  // Called whenever a remote car goes up or down.
  std::function<void()> onChange;

  // Used by RemoteLink: publishes the command's intent; nullopt when published, else why not.
  std::optional<std::string> sendCommand(const std::string& car,
                                         std::span<const std::uint8_t> frame);
  // Used by RemoteLink: the stop `frame` as an intent published on a connection of its own,
  // for the watchdog's thread (engine/core/emergency_stops.hpp); null for a spectator.
  emergency::Stopper emergencyStopper(const std::string& car,
                                      std::span<const std::uint8_t> frame) const;

 private:
  struct Car {
    RemoteLink* link = nullptr;  // owned by the fleet once added
    std::optional<topics::CarInfo> info;
    std::optional<bool> online;  // its S/CarStatus, once one came
    std::string host;            // from the hosts' S/Cars; empty while unknown
    bool listed = false;         // in its host's S/Cars now
    bool everListed = false;     // some S/Cars named it
    bool present() const;        // its bridge has it connected
    // Its kind, from what its bridge says in S/Information (topics::CarInfo::pitwall), never
    // from which events came first: a pitwall bridge's car is fed by E/frame and takes every
    // command; any other is the seed's controller's, fed by E/Messages, and takes its intents.
    bool pitwall() const { return info && info->pitwall; }
    bool seed() const { return info && !info->pitwall; }
    // The information is the word of the host that has the car now: a pitwall bridge's
    // S/Information names its host, and once another host's S/Cars lists the car, it is stale.
    bool infoCurrent() const { return !pitwall() || host.empty() || info->host == host; }
  };
  void message(std::string_view topic, std::string_view payload);
  void handle(std::string_view topic, std::string_view payload);
  void warn(const std::string& line);  // rate-limited: a flood of junk is not a flood of logs
  void update(const std::string& id, Car& car);
  bool hostUp(const std::string& host) const;
  std::string uniqueName(const topics::CarInfo& info) const;
  // The entry of car `id`, made when there is room (kMaxTracked); nullptr, with a warning, when
  // the tree names more cars than any fleet has (a hostile publisher inventing ids).
  Car* track(const std::string& id, std::string_view topic);
  std::size_t linkedCount() const;

  Loop& loop_;
  Fleet& fleet_;
  MqttClient& client_;
  topics::PayloadLimits limits_;
  TokenBucket warnings_;
  std::uint64_t unlogged_ = 0;  // warnings beyond the limit since the last one logged
  std::string syncTopic_;
  std::map<std::string, Car> cars_;
  std::map<std::string, bool> hosts_;  // HostStatus as last published
  bool brokerUp_ = false;
  bool readOnly_ = false;
  std::function<void()> synced_;
  std::function<void(const std::string&)> failed_;
};

}  // namespace pitwall
