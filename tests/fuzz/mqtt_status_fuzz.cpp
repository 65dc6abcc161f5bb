// The readers a remote pitwall applies to what bridges publish (engine/mqtt/topics.hpp:
// splitTopic, readInformation, readCarStatus, readHostStatus, readHostCars, readFrameEvent,
// readMessageEvent). The first input byte picks the reader, the rest is the payload (or the
// topic). Never a crash or an exception; an error is a sentence. What a reader accepts survives
// the round trip through the bridge's writer: carJoined's S/Information, hostCars, frameEvent and
// carOnline/carLeft read back to the same values, a message read from the seed's controller's
// E/Messages event is published by fromMessage as the same event and reads back as the same
// message (offsets to the 0.01 mm the writer keeps), and a topic splitTopic accepts is rebuilt
// from its parts.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "engine/mqtt/topics.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

namespace {

template <class R>
void checkError(const R& r, const std::string& payload) {
  if (!r) FUZZ_CHECK(!r.error().empty(), payload);
}

void information(const std::string& payload) {
  auto info = topics::readInformation("e85a0f112233", payload);
  checkError(info, payload);
  if (!info) return;
  const auto published = topics::carJoined(*info, CarState{}, 1);
  FUZZ_CHECK(!published.empty() && published[0].topic.ends_with("/S/Information"), payload);
  auto again = topics::readInformation(info->id, published[0].payload);
  FUZZ_CHECK(again.ok(), payload + " → " + published[0].payload);
  FUZZ_CHECK(again->id == info->id && again->address == info->address &&
                 again->identifier == info->identifier && again->model_id == info->model_id &&
                 again->product_id == info->product_id && again->name == info->name,
             payload + " → " + published[0].payload);
}

void carStatus(const std::string& payload) {
  auto status = topics::readCarStatus(payload);
  checkError(status, payload);
  if (!status) return;
  CarState state;
  state.on_charger = status->charging;
  state.on_track = status->onTrack;
  const auto p = status->online ? topics::carOnline("c", state, 1) : topics::carLeft("c", state, 1);
  auto again = topics::readCarStatus(p.payload);
  FUZZ_CHECK(again.ok() && again->online == status->online && again->charging == status->charging &&
                 again->onTrack == status->onTrack,
             payload + " → " + p.payload);
}

void hostStatus(const std::string& payload) {
  auto online = topics::readHostStatus(payload);
  checkError(online, payload);
  if (!online) return;
  const auto p = *online ? topics::hostOnline("h") : topics::hostWill("h");
  auto again = topics::readHostStatus(p.payload);
  FUZZ_CHECK(again.ok() && *again == *online, payload + " → " + p.payload);
}

void hostCars(const std::string& payload) {
  auto cars = topics::readHostCars(payload);
  checkError(cars, payload);
  if (!cars) return;
  const auto p = topics::hostCars("h", *cars);
  auto again = topics::readHostCars(p.payload);
  FUZZ_CHECK(again.ok() && *again == *cars, payload + " → " + p.payload);
}

void frameEvent(const std::string& payload) {
  auto frame = topics::readFrameEvent(payload);
  checkError(frame, payload);
  if (!frame) return;
  const auto p = topics::frameEvent("c", *frame, 1);
  auto again = topics::readFrameEvent(p.payload);
  FUZZ_CHECK(again.ok() && *again == *frame, payload + " → " + p.payload);
}

// The names of the controller's whole-message events, one per message it publishes.
const std::vector<std::string> kMessageEvents{
    "ANKI_VEHICLE_MSG_V2C_PING_RESPONSE",
    "ANKI_VEHICLE_MSG_V2C_VERSION_RESPONSE",
    "ANKI_VEHICLE_MSG_V2C_BATTERY_LEVEL_RESPONSE",
    "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE",
    "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_TRANSITION_UPDATE",
    "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_INTERSECTION_UPDATE",
    "ANKI_VEHICLE_MSG_V2C_VEHICLE_DELOCALIZED",
    "ANKI_VEHICLE_MSG_V2C_VEHICLE_STATUS",
};

// Offsets are kept to 0.01 mm by the writer: compare messages with them rounded so.
anki::Message rounded(anki::Message m) {
  std::visit(
      [](auto& x) {
        if constexpr (requires { x.offset_mm; })
          x.offset_mm =
              static_cast<float>(std::round(static_cast<double>(x.offset_mm) * 100) / 100);
      },
      m);
  return m;
}

void messageEvent(const std::string& text) {
  if (text.empty()) return;
  const std::string& name = kMessageEvents[static_cast<unsigned char>(text[0]) % 8];
  const std::string payload = text.substr(1);
  auto read = topics::readMessageEvent(name, payload);
  checkError(read, payload);
  if (!read) return;
  FUZZ_CHECK(read->has_value(), name + " " + payload);
  const auto& m = **read;
  FUZZ_CHECK(topics::messageEventName(m) == name, payload);
  (void)anki::encode(m);  // every message read is one a frame can carry
  const auto published = topics::fromMessage("c", m, std::nullopt, 1);
  FUZZ_CHECK(!published.empty() && published.back().topic == "Anki/Car/c/E/Messages/" + name,
             payload);
  auto again = topics::readMessageEvent(name, published.back().payload);
  FUZZ_CHECK(again.ok() && again->has_value() && rounded(**again) == rounded(m),
             payload + " → " + published.back().payload);
}

void topic(const std::string& text) {
  auto parts = topics::splitTopic(text);
  if (!parts) return;
  FUZZ_CHECK(!parts->id.empty(), text);
  const std::string kind = parts->kind == topics::TopicParts::Kind::Car ? "Car" : "Host";
  FUZZ_CHECK("Anki/" + kind + "/" + parts->id + "/" + parts->rest == text, text);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(data + 1, data + size);
  switch (data[0] % 7) {
    case 0:
      information(text);
      break;
    case 1:
      carStatus(text);
      break;
    case 2:
      hostStatus(text);
      break;
    case 3:
      hostCars(text);
      break;
    case 4:
      frameEvent(text);
      break;
    case 5:
      messageEvent(text);
      break;
    default:
      topic(text);
  }
  return 0;
}
