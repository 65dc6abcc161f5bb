// The MQTT intent parser (engine/mqtt/topics.hpp: parseIntent, intentError,
// intentPayload): what anyone who can publish on the broker sends to a bridge. The first input
// byte picks the topic (the intent topics of host "pitA" and the seed's controller's global
// Anki/Car/I, or a topic taken from the input up to a NUL byte); the rest is the payload. Never a
// crash or an exception; a refused intent's error is a sentence, and its S/IntentError payload is
// valid JSON naming the topic. Control byte 6: the rest is an Anki frame instead. A
// controller→vehicle message in range (limits::validate) has an intent payload (intentPayload, what
// a remote pitwall publishes), and the bridge's parser accepts that payload on the car's intent
// topic; a "message" intent carries the very same message.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/mqtt/topics.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/limits.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

namespace {

constexpr const char* kHost = "pitA";
const std::vector<std::string> kCars{"e85a0f112233", "sim-0000002a"};

void intent(std::string_view topic, std::string_view payload) {
  auto parsed = topics::parseIntent(kHost, topic, payload, kCars);
  if (parsed) return;
  FUZZ_CHECK(parsed.error().topic == topic && !parsed.error().message.empty());
  const topics::Publication p = topics::intentError(kHost, parsed.error(), 1);
  const auto j = nlohmann::json::parse(p.payload, nullptr, false);
  FUZZ_CHECK(!j.is_discarded() && j.is_object() && j.contains("topic") && j.contains("error"),
             p.payload);
}

void commandRoundTrip(std::span<const std::uint8_t> frame) {
  auto m = anki::decode(frame);
  if (!m) return;
  auto payload = topics::intentPayload(*m);
  if (!payload || anki::limits::validate(*m)) return;
  const std::string topic = "Anki/Car/" + kCars[0] + "/I";
  auto parsed = topics::parseIntent(kHost, topic, *payload, kCars);
  FUZZ_CHECK(parsed.ok(), fuzz::bytesText("frame", frame) + " as " + *payload + ": " +
                              (parsed ? std::string() : parsed.error().message));
  FUZZ_CHECK(parsed->target.kind == topics::Target::Kind::Car && parsed->target.car == kCars[0]);
  if (const auto* carried = std::get_if<topics::MessageIntent>(&parsed->action)) {
    FUZZ_CHECK(anki::encode(carried->message) == anki::encode(*m), *payload);
  }
  if (const auto* speed = std::get_if<topics::SpeedIntent>(&parsed->action)) {
    const auto& sent = std::get<anki::SetSpeed>(*m);
    FUZZ_CHECK(speed->speed_mm_s == sent.speed_mm_s && speed->accel_mm_s2 == sent.accel_mm_s2,
               *payload);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  const std::string text(rest.begin(), rest.end());
  switch (data[0] % 7) {
    case 0:
      intent("Anki/Host/pitA/I/connection", text);
      break;
    case 1:
      intent("Anki/Host/pitA/I", text);
      break;
    case 2:
      intent("Anki/Car/all/I", text);
      break;
    case 3:
      intent("Anki/Car/" + kCars[0] + "/I", text);
      break;
    case 4: {
      const auto parts = fuzz::splitAt(rest, 0);
      intent(parts.first, parts.second);
      break;
    }
    case 5:
      intent("Anki/Car/I", text);
      break;
    default:
      commandRoundTrip(rest);
  }
  return 0;
}
