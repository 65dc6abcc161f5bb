#pragma once
// What anyone who can publish on the broker might send instead of a payload of the tree
// (docs/mqtt.md "Hostile input"), for the tests of both sides: the bridge reading intents and
// remote cars reading status, events and frames. None of them may crash the process, and an
// error about one quotes at most 80 bytes of it, escaped.
#include <string>
#include <vector>

namespace pitwall::testing {

struct HostilePayload {
  std::string name;
  std::string payload;
  std::string error;  // part of the sentence a bridge answers it with, as an intent
};

// `depth` arrays around `inner`.
inline std::string nested(int depth, const std::string& inner) {
  return std::string(depth, '[') + inner + std::string(depth, ']');
}

// A valid speed intent, padded with spaces to exactly `bytes`.
inline std::string paddedSpeedIntent(std::size_t bytes, int speed = 600) {
  std::string intent =
      R"({"type":"speed","speed":)" + std::to_string(speed) + R"(,"acceleration":1000})";
  return intent + std::string(bytes - intent.size(), ' ');
}

// A valid speed intent whose extra key holds arrays nested so that the payload is `depth` deep.
inline std::string deepSpeedIntent(int depth, int speed = 600) {
  return R"({"type":"speed","speed":)" + std::to_string(speed) + R"(,"acceleration":1000,"x":)" +
         nested(depth - 1, "0") + "}";
}

inline std::vector<HostilePayload> hostilePayloads() {
  std::string garbage;
  for (int i = 0; i < 1024; ++i) garbage += static_cast<char>((i * 37) % 256);
  return {
      {"a number beyond a double", "5e999", "number beyond the range of a double"},
      {"an offset beyond a double", R"({"type":"lane","offset":1e400})",
       "number beyond the range of a double"},
      {"an offset of 401 digits", R"({"type":"lane","offset":1)" + std::string(400, '0') + "}",
       "number beyond the range of a double"},
      {"a huge integer", R"({"type":"speed","speed":99999999999999999999999,"acceleration":1})",
       "\"speed\" must be an integer, not a number"},
      {"invalid UTF-8 in a string value", "{\"type\":\"speed\",\"note\":\"\xff\xfe\"}",
       "ill-formed UTF-8"},
      {"invalid UTF-8 in a key", "{\"ty\xc3\x28pe\":\"speed\"}", "ill-formed UTF-8"},
      {"an encoded UTF-16 surrogate", "{\"type\":\"\xed\xa0\x80\"}", "ill-formed UTF-8"},
      {"invalid UTF-8 outside strings", "{\"type\":\xff}", "payload is not JSON"},
      {"invalid UTF-8 after 60 KB of a string",
       "{\"type\":\"" + std::string(60000, 'a') + "\xc0\xaf\"}", "ill-formed UTF-8"},
      {"a 60 KB string", "{\"type\":\"" + std::string(60000, 'x') + "\"}",
       "unknown intent type \"xxxx"},
      {"NaN", R"({"type":"lane","offset":NaN})", "payload is not JSON"},
      {"-Infinity", R"({"type":"lane","offset":-Infinity})", "payload is not JSON"},
      {"binary garbage", garbage, "payload is not JSON"},
      {"arrays nested 100 000 deep (200 KB)", nested(100000, ""), "more than 65536"},
      {"arrays opened 30 000 deep", std::string(30000, '['), "more than 64 deep"},
      {"objects opened 10 000 deep",
       [] {
         std::string s;
         for (int i = 0; i < 10000; ++i) s += "{\"a\":";
         return s;
       }(),
       "more than 64 deep"},
      {"nesting one beyond the limit (65)", deepSpeedIntent(65), "more than 64 deep"},
      {"1 MB", "{\"type\":\"speed\",\"pad\":\"" + std::string(1 << 20, 'x') + "\"}",
       "more than 65536"},
      {"64 KB + 1 byte", paddedSpeedIntent(64 * 1024 + 1), "65537 bytes, more than 65536"},
  };
}

}  // namespace pitwall::testing
