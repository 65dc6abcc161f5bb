#include "engine/record/results.hpp"

#include "engine/core/numbers.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace pitwall::results {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool whole(double v) {
  return std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15;
}

// Times (seconds) are results to the millisecond: every number with a fraction is written
// rounded to three decimals (62.3456789 → 62.346), whatever its size.
double toMillis(double v) {
  if (!std::isfinite(v) || std::fabs(v) >= 1e12) return v;
  return std::round(v * 1000) / 1000;
}

std::string number(double v) {
  v = toMillis(v);
  if (whole(v)) return std::to_string(static_cast<long long>(v));
  if (!std::isfinite(v) || std::fabs(v) >= 1e12) return formatNumber(v, 6);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  std::string text = buf;
  while (text.back() == '0') text.pop_back();  // a fraction is there: never reaches the point
  return text;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace

Result<Format, std::string> formatOf(const std::string& path) {
  auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : lower(path.substr(dot));
  if (ext == ".json") return Format::Json;
  if (ext == ".csv") return Format::Csv;
  return Unexpected{"results file '" + path +
                    "' must end in .json or .csv (that picks the format)"};
}

std::string render(const Table& table, Format format) {
  if (format == Format::Json) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const auto& row : table.rows) {
      nlohmann::ordered_json o = nlohmann::ordered_json::object();
      for (std::size_t i = 0; i < table.columns.size(); ++i) {
        const Cell& c = i < row.size() ? row[i] : Cell{};
        if (auto* d = std::get_if<double>(&c)) {
          const double v = toMillis(*d);
          o[table.columns[i]] = whole(v) ? nlohmann::ordered_json(static_cast<long long>(v))
                                         : nlohmann::ordered_json(v);
        } else if (auto* s = std::get_if<std::string>(&c))
          o[table.columns[i]] = *s;
        else if (auto* b = std::get_if<bool>(&c))
          o[table.columns[i]] = *b;
        else
          o[table.columns[i]] = nullptr;
      }
      out.push_back(std::move(o));
    }
    return out.dump(2) + "\n";
  }
  std::ostringstream out;
  for (std::size_t i = 0; i < table.columns.size(); ++i)
    out << (i ? "," : "") << csvField(table.columns[i]);
  out << "\n";
  for (const auto& row : table.rows) {
    for (std::size_t i = 0; i < table.columns.size(); ++i) {
      if (i) out << ",";
      const Cell& c = i < row.size() ? row[i] : Cell{};
      if (auto* d = std::get_if<double>(&c))
        out << number(*d);
      else if (auto* s = std::get_if<std::string>(&c))
        out << csvField(*s);
      else if (auto* b = std::get_if<bool>(&c))
        out << (*b ? "true" : "false");
    }
    out << "\n";
  }
  return out.str();
}

Result<bool, std::string> writable(const std::string& path) {
  auto format = formatOf(path);
  if (!format) return Unexpected{format.error()};
  std::string probe = path + ".tmp";
  std::ofstream f(probe, std::ios::binary | std::ios::trunc);
  if (!f)
    return Unexpected{"cannot write results to '" + path + "': its folder does not take files"};
  f.close();
  std::remove(probe.c_str());
  return true;
}

Result<bool, std::string> write(const std::string& path, const Table& table) {
  auto format = formatOf(path);
  if (!format) return Unexpected{format.error()};
  return writeText(path, render(table, *format), "results");
}

Result<bool, std::string> writeText(const std::string& path, const std::string& text,
                                    const std::string& what) {
  std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return Unexpected{"cannot write " + what + " to '" + path + "': cannot create " + tmp};
    f << text;
    if (!f.flush()) return Unexpected{"cannot write " + what + " to '" + path + "'"};
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return Unexpected{"cannot write " + what + " to '" + path + "': rename failed"};
  }
  return true;
}

}  // namespace pitwall::results
