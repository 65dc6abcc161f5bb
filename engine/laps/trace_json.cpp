#include "engine/laps/trace_json.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace pitwall::laps {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json rounded(double v) {
  if (!std::isfinite(v)) return nullptr;
  const double r = std::round(v * 1000) / 1000;
  return r == 0 ? 0.0 : r;
}

// A finite number, or NaN for null when `nullable`; none when it is anything else.
std::optional<double> number(const nlohmann::json& j, bool nullable) {
  if (j.is_null() && nullable) return kNaN;
  if (!j.is_number()) return std::nullopt;
  const double v = j.get<double>();
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

nlohmann::json traceJson(const LapTrace& trace) {
  nlohmann::json points = nlohmann::json::array();
  for (const TracePoint& p : trace.points)
    points.push_back({rounded(p.t), rounded(p.distance), rounded(p.speed), rounded(p.offset)});
  nlohmann::json entered = nlohmann::json::array();
  for (double t : trace.pieceEntered) entered.push_back(rounded(t));
  nlohmann::json reported = nlohmann::json::array();
  for (bool r : trace.pieceReported) reported.push_back(r ? 1 : 0);
  return {{"lap", trace.lap}, {"time", rounded(trace.time)}, {"length", rounded(trace.length)},
          {"points", points}, {"entered", entered},          {"reported", reported}};
}

Result<LapTrace, std::string> traceFromJson(const nlohmann::json& json) {
  if (!json.is_object()) return Unexpected{std::string("a kept lap is not a JSON object")};
  LapTrace trace;
  auto field = [&](const char* name) -> const nlohmann::json* {
    auto it = json.find(name);
    return it == json.end() ? nullptr : &*it;
  };
  const auto* lap = field("lap");
  const auto* time = field("time");
  const auto* length = field("length");
  const auto* points = field("points");
  if (!lap || !lap->is_number_integer() || !time || !length || !points || !points->is_array())
    return Unexpected{std::string("a kept lap lacks its lap, time, length or points")};
  trace.lap = static_cast<int>(std::clamp<std::int64_t>(lap->get<std::int64_t>(), 0, 1 << 30));
  auto t = number(*time, false);
  auto l = number(*length, false);
  if (!t || !l || *t <= 0 || *l <= 0)
    return Unexpected{std::string("a kept lap's time and length must be numbers above 0")};
  trace.time = *t;
  trace.length = *l;
  if (points->size() < 2 || points->size() > kMaxTracePoints)
    return Unexpected{"a kept lap has " + std::to_string(points->size()) +
                      " points; it needs 2 to " + std::to_string(kMaxTracePoints)};
  for (const auto& p : *points) {
    if (!p.is_array() || p.size() != 4)
      return Unexpected{std::string("a kept lap's point is not [t, distance, speed, offset]")};
    auto pt = number(p[0], false);
    auto pd = number(p[1], false);
    auto ps = number(p[2], true);
    auto po = number(p[3], true);
    if (!pt || !pd || !ps || !po)
      return Unexpected{std::string("a kept lap's point holds something other than numbers")};
    if (!trace.points.empty() &&
        (*pt < trace.points.back().t || *pd < trace.points.back().distance))
      return Unexpected{std::string("a kept lap's points go back in time or distance")};
    trace.points.push_back({*pt, *pd, *ps, *po});
  }
  if (trace.points.front().t != 0 || trace.points.front().distance != 0 ||
      std::abs(trace.points.back().t - trace.time) > 1e-3 ||
      std::abs(trace.points.back().distance - trace.length) > 1e-3)
    return Unexpected{std::string("a kept lap does not run from the line round to the line")};
  if (const auto* entered = field("entered"); entered && entered->is_array()) {
    if (entered->size() > kMaxTracePoints)
      return Unexpected{std::string("a kept lap has more pieces than any track")};
    for (const auto& e : *entered) {
      auto v = number(e, true);
      if (!v) return Unexpected{std::string("a kept lap's piece times are not numbers")};
      trace.pieceEntered.push_back(*v);
    }
  }
  if (const auto* reported = field("reported"); reported && reported->is_array()) {
    if (reported->size() > kMaxTracePoints)
      return Unexpected{std::string("a kept lap has more pieces than any track")};
    for (const auto& r : *reported) trace.pieceReported.push_back(r == 1);
  }
  return trace;
}

}  // namespace pitwall::laps
