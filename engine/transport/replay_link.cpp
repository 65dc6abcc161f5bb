#include "engine/transport/replay_link.hpp"

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/message_json.hpp"

namespace pitwall {

ReplayLink::ReplayLink(std::string label) : label_(std::move(label)) {}

void ReplayLink::connect() {
  if (connected_) return;
  connected_ = true;
  // what the controller sends every car it connects (SDK mode, the version and battery asked)
  // is no news in a replay: said at debug, not once per car before the table
  handshake_ = true;
  deliverState(true, "");
  handshake_ = false;
}

void ReplayLink::recorded(bool up, const std::string& reason, const LinkHealth& health) {
  health_ = health;
  if (up) return connect();
  if (!connected_) return;
  connected_ = false;
  deliverState(false, reason);
}

void ReplayLink::disconnect() {
  if (!connected_) return;
  connected_ = false;
  deliverState(false, "disconnected");
}

bool ReplayLink::send(std::span<const std::uint8_t> frame) {
  if (!connected_) return false;
  // "set-speed {"accel_mm_s2":1000,…}": the name and the fields, as `pitwall decode` shows them
  std::string text;
  if (auto decoded = anki::decode(frame)) {
    auto j = anki::toJson(*decoded);
    text = j.value("name", std::string("frame"));
    j.erase("name");
    j.erase("id");
    if (!j.empty()) text += " " + j.dump();
  } else {
    text = "frame " + toHex(frame);
  }
  log::write(handshake_ ? log::Level::Debug : log::Level::Info, label_,
             text + " not sent: a replay");
  return true;
}

}  // namespace pitwall
