#include "engine/print/svg_metadata.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "engine/print/code_options.hpp"

namespace pitwall::print {

namespace {

constexpr std::string_view kElement = "<pitwall:piece ";

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

// The value of attribute `name` within one element's text, or nothing.
bool attribute(std::string_view element, std::string_view name, std::string& out) {
  const std::string key = " " + std::string(name) + "=\"";
  const auto at = element.find(key);
  if (at == std::string_view::npos) return false;
  const auto from = at + key.size();
  const auto to = element.find('"', from);
  if (to == std::string_view::npos) return false;
  out = std::string(element.substr(from, to - from));
  return true;
}

// code-NAME-mm, '_' as '-': "code-stroke-pitch-mm".
std::string codeAttribute(std::string_view name) {
  std::string out = "code-" + std::string(name) + "-mm";
  for (char& c : out)
    if (c == '_') c = '-';
  return out;
}

bool attribute(std::string_view element, std::string_view name, double& out) {
  std::string s;
  if (!attribute(element, name, s)) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size() && std::isfinite(out);
}

std::string codeAttributes(const sim::CodeGeometry& g) {
  std::string out;
  for (const auto& d : codeDimensions())
    out += " " + codeAttribute(d.name) + "=\"" + number(g.*(d.field)) + "\"";
  return out;
}

}  // namespace

// A token (sim::pieceToken, or "start") holds letters, digits and ":,=." only: nothing XML would
// need escaped, in an attribute or read back from one.
std::string withMetadata(std::string_view svg, const PieceSvg& piece) {
  const std::string element =
      "<metadata id=\"pitwall-piece\"><pitwall:piece xmlns:pitwall=\"urn:pitwall:piece:1\" "
      "token=\"" +
      piece.token + "\" piece-id=\"" + std::to_string(piece.piece_id) + "\" width-mm=\"" +
      number(piece.sheet.width_mm) + "\" height-mm=\"" + number(piece.sheet.height_mm) +
      "\" start-x-mm=\"" + number(piece.sheet.origin_x_mm) + "\" start-y-mm=\"" +
      number(piece.sheet.origin_y_mm) + "\" start-heading=\"+x\"" + codeAttributes(piece.code) +
      "/></metadata>\n";
  const auto svgTag = svg.find("<svg");
  const auto close = svgTag == std::string_view::npos ? svg.npos : svg.find('>', svgTag);
  if (close == std::string_view::npos) return std::string(svg);
  std::string out(svg.substr(0, close + 1));
  out += "\n" + element;
  out += svg.substr(close + 1);
  return out;
}

Result<PieceSvg, std::string> readMetadata(std::string_view svg) {
  const auto at = svg.find(kElement);
  if (at == std::string_view::npos)
    return Unexpected<std::string>(std::string("it has no pitwall piece metadata"));
  const auto end = svg.find("/>", at);
  if (end == std::string_view::npos)
    return Unexpected<std::string>(std::string("its pitwall piece metadata is cut short"));
  const std::string_view element = svg.substr(at, end - at);
  PieceSvg p;
  std::string raw;
  if (!attribute(element, "token", raw) || raw.empty())
    return Unexpected<std::string>(std::string("its pitwall piece metadata has no token"));
  p.token = raw;
  double id = -1;
  if (!attribute(element, "piece-id", id) || id < 0 || id > 255 || id != std::floor(id))
    return Unexpected<std::string>(std::string("its pitwall piece metadata has no piece-id"));
  p.piece_id = static_cast<int>(id);
  for (auto [name, field] :
       {std::pair{"width-mm", &p.sheet.width_mm}, std::pair{"height-mm", &p.sheet.height_mm},
        std::pair{"start-x-mm", &p.sheet.origin_x_mm},
        std::pair{"start-y-mm", &p.sheet.origin_y_mm}})
    if (!attribute(element, name, *field))
      return Unexpected<std::string>(std::string("its pitwall piece metadata has no number ") +
                                     name);
  if (p.sheet.width_mm <= 0 || p.sheet.height_mm <= 0)
    return Unexpected<std::string>(std::string("its pitwall piece metadata gives an empty sheet"));
  // The code's dimensions: each one absent keeps its default (an SVG from before they were
  // written); one present must be a number, and together they must be readable.
  for (const auto& d : codeDimensions()) {
    const std::string name = codeAttribute(d.name);
    std::string raw;
    if (!attribute(element, name, raw)) continue;
    if (!attribute(element, name, p.code.*(d.field)))
      return Unexpected<std::string>("its pitwall piece metadata has no number " + name);
  }
  if (auto problem = codeProblem(p.code))
    return Unexpected<std::string>(
        "its pitwall piece metadata gives code dimensions no sensor "
        "reads: " +
        *problem);
  return p;
}

}  // namespace pitwall::print
