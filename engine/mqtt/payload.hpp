#pragma once
// Private to engine/mqtt: the JSON both directions of the topic tree share — how a payload from the
// broker is read (its size first, a depth limit, every exception of the parser a sentence), how a
// received value is shown in an error, and the topic names and rounding pitwall's publications
// use. The public API is engine/mqtt/topics.hpp.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/mqtt/topics.hpp"

namespace pitwall::topics::detail {

// What pitwall writes keeps its keys in the order written (golden strings stay stable); what it
// reads is parsed into a map: ordered_json finds a key by a linear search, so a payload of
// thousands of distinct keys would cost quadratic time before any rate limit is applied.
using Json = nlohmann::ordered_json;
using In = nlohmann::json;

constexpr int kEventQos = 0;   // events: QoS 0, not retained (mqtt-topics.md)
constexpr int kStatusQos = 1;  // status: QoS 1, retained

inline std::string carTopic(std::string_view car, std::string_view rest) {
  return "Anki/Car/" + std::string(car) + "/" + std::string(rest);
}
inline std::string hostTopic(std::string_view host, std::string_view rest) {
  return "Anki/Host/" + std::string(host) + "/" + std::string(rest);
}

// Offsets are floats on the wire; 0.01 mm is far below what a car measures, and rounding keeps
// payloads free of float noise (-23.1f would print as -23.100000381469727).
inline double mm(double v) {
  return std::round(v * 100.0) / 100.0;
}

// At most `n` bytes of a sentence of ours, cut between two UTF-8 characters, then "…".
std::string clip(std::string_view s, std::size_t n);
// A value received, as an error message shows it: its JSON, cut and escaped (a string value of
// 60 KB stays a short sentence).
std::string excerpt(const In& v);
// "an integer", "a number", "a string", "an object", … for error sentences.
std::string typeName(const In& v);
// The one way a payload from the broker becomes JSON: size first, then a parse that stops at the
// depth limit; every exception of the parser becomes an error sentence.
Result<In, std::string> parse(std::string_view payload, const PayloadLimits& limits);
// parse(), and the payload must be a JSON object.
Result<In, std::string> object(std::string_view payload, const PayloadLimits& limits);
// A topic's levels ("Anki/Car/x/I" → Anki, Car, x, I).
std::vector<std::string_view> split(std::string_view s);

}  // namespace pitwall::topics::detail
