#include "engine/view/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

namespace pitwall::view {

namespace {

// `fraction` along piece `p` that begins at `start`, `offset_mm` right of its centre line.
Pose onPiece(const sim::Piece& p, const Pose& start, double fraction, double offset_mm) {
  return sim::poseOnPiece(p, start, fraction, offset_mm);
}

double normalize(double degrees) {
  double d = std::fmod(degrees, 360.0);
  if (d < 0) d += 360;
  if (std::abs(d) < 1e-9 || std::abs(d - 360) < 1e-9) d = 0;
  return d;
}

double clean(double v) {
  double r = std::round(v * 1000) / 1000;
  return r == 0 ? 0 : r;  // never "-0"
}

}  // namespace

Pose pieceStart(const sim::Track& track, std::size_t index) {
  Pose at;
  for (std::size_t i = 0; i < index && i < track.size(); ++i) {
    at = onPiece(track.pieces()[i], at, 1.0, 0);
    at.heading = normalize(at.heading);
  }
  return at;
}

Pose pointOnTrack(const sim::Track& track, std::size_t index, double fraction, double offset_mm) {
  if (track.size() == 0) return {};
  index %= track.size();
  Pose p = onPiece(track.pieces()[index], pieceStart(track, index), std::clamp(fraction, 0.0, 1.0),
                   offset_mm);
  p.heading = normalize(p.heading);
  return p;
}

nlohmann::json trackJson(const sim::Track& track, const std::string& source) {
  nlohmann::json pieces = nlohmann::json::array();
  double minX = 0, minY = 0, maxX = 0, maxY = 0;
  Pose at;
  auto extend = [&](const Pose& p) {
    minX = std::min(minX, p.x), maxX = std::max(maxX, p.x);
    minY = std::min(minY, p.y), maxY = std::max(maxY, p.y);
  };
  nlohmann::json finish = nullptr;
  for (std::size_t i = 0; i < track.size(); ++i) {
    const sim::Piece& p = track.pieces()[i];
    if (p.type == anki::PieceType::StartShort)
      finish = {{"x", clean(at.x)}, {"y", clean(at.y)}, {"heading", clean(at.heading)}};
    pieces.push_back({{"index", i},
                      {"id", p.id},
                      {"type", std::string(anki::pieceTypeName(p.type))},
                      {"turn", p.turn},
                      {"length", clean(p.length(0))},
                      {"radius", p.turn ? nlohmann::json(p.radius()) : nullptr},
                      {"x", clean(at.x)},
                      {"y", clean(at.y)},
                      {"heading", clean(at.heading)}});
    // the road's edges along the piece bound the drawing
    for (double f : {0.0, 0.25, 0.5, 0.75, 1.0})
      for (double o : {-kRoadHalfWidthMm, kRoadHalfWidthMm}) extend(onPiece(p, at, f, o));
    at = onPiece(p, at, 1.0, 0);
    at.heading = normalize(at.heading);
  }
  nlohmann::json lanes = nlohmann::json::array();
  for (double o : kLaneOffsetsMm) lanes.push_back(o);
  return {{"name", track.name()},
          {"source", source},
          {"roadHalfWidth", kRoadHalfWidthMm},
          {"lanes", lanes},
          {"lapLength", clean(track.lapLength(0))},
          {"pieces", pieces},
          {"finish", finish},
          {"bounds",
           {{"minX", clean(minX)},
            {"minY", clean(minY)},
            {"maxX", clean(maxX)},
            {"maxY", clean(maxY)}}}};
}

namespace {

// An SVG path along `offset` of every piece (y flipped: SVG's y goes down).
std::string lanePath(const sim::Track& track, double offset) {
  std::ostringstream d;
  d.precision(1);
  d << std::fixed;
  Pose at;
  for (std::size_t i = 0; i < track.size(); ++i) {
    const sim::Piece& p = track.pieces()[i];
    Pose a = onPiece(p, at, 0, offset), b = onPiece(p, at, 1, offset);
    if (i == 0) d << "M" << a.x << " " << -a.y;
    if (p.turn == 0) {
      d << " L" << b.x << " " << -b.y;
    } else {
      double r = p.radius() + p.turn * offset;
      // a left turn is counter-clockwise in y-up, clockwise once y is flipped: sweep flag 0
      d << " A" << r << " " << r << " 0 " << (p.angle() > 180 ? 1 : 0) << " "
        << (p.turn > 0 ? 0 : 1) << " " << b.x << " " << -b.y;
    }
    at = onPiece(p, at, 1.0, 0);
  }
  return d.str();
}

}  // namespace

std::string trackSvg(const sim::Track& track) {
  auto json = trackJson(track, "layout");
  const auto& b = json["bounds"];
  const double margin = 60;
  const double minX = b["minX"].get<double>() - margin, maxX = b["maxX"].get<double>() + margin;
  const double minY = b["minY"].get<double>() - margin, maxY = b["maxY"].get<double>() + margin;
  std::ostringstream svg;
  svg.precision(1);
  svg << std::fixed;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"" << minX << " " << -maxY << " "
      << (maxX - minX) << " " << (maxY - minY) << "\" width=\"" << (maxX - minX) / 4
      << "mm\" height=\"" << (maxY - minY) / 4 << "mm\">\n";
  svg << "<title>" << track.name() << ": " << track.size() << " pieces, lap " << track.lapLength(0)
      << " mm</title>\n";
  svg << "<rect x=\"" << minX << "\" y=\"" << -maxY << "\" width=\"" << (maxX - minX)
      << "\" height=\"" << (maxY - minY) << "\" fill=\"#1b1f24\"/>\n";
  svg << "<path class=\"road\" d=\"" << lanePath(track, 0)
      << "\" fill=\"none\" stroke=\"#3a3f47\" stroke-width=\"" << 2 * kRoadHalfWidthMm
      << "\" stroke-linejoin=\"round\"/>\n";
  for (double o : kLaneOffsetsMm)
    svg << "<path class=\"lane\" d=\"" << lanePath(track, o)
        << "\" fill=\"none\" stroke=\"#6b7380\" stroke-width=\"3\" stroke-dasharray=\"20 20\"/>\n";
  if (!json["finish"].is_null()) {
    Pose f{json["finish"]["x"], json["finish"]["y"], json["finish"]["heading"]};
    sim::Piece straight;
    Pose l = onPiece(straight, f, 0, -kRoadHalfWidthMm),
         r = onPiece(straight, f, 0, kRoadHalfWidthMm);
    svg << "<line id=\"finish-line\" x1=\"" << l.x << "\" y1=\"" << -l.y << "\" x2=\"" << r.x
        << "\" y2=\"" << -r.y << "\" stroke=\"#ffffff\" stroke-width=\"16\" "
        << "stroke-dasharray=\"16 16\"/>\n";
  }
  for (const auto& p : json["pieces"]) {
    Pose mid =
        onPiece(track.pieces()[p["index"].get<std::size_t>()],
                {p["x"].get<double>(), p["y"].get<double>(), p["heading"].get<double>()}, 0.5, 0);
    svg << "<text x=\"" << mid.x << "\" y=\"" << -mid.y + 14
        << "\" font-size=\"40\" font-family=\"sans-serif\" fill=\"#e6e6e6\" "
        << "text-anchor=\"middle\">" << p["id"].get<int>() << "</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string trackSummary(const sim::Track& track) {
  auto json = trackJson(track, "layout");
  const auto& b = json["bounds"];
  char line[256];
  std::string out = track.name() + ": " + std::to_string(track.size()) + " pieces\n";
  for (const auto& p : json["pieces"]) {
    const sim::Piece& piece = track.pieces()[p["index"].get<std::size_t>()];
    std::snprintf(line, sizeof line, "  %2zu  id %-3d %-11s %s", p["index"].get<std::size_t>(),
                  p["id"].get<int>(), p["type"].get<std::string>().c_str(),
                  p["turn"].get<int>() > 0   ? "left"
                  : p["turn"].get<int>() < 0 ? "right"
                                             : "");
    out += line;
    if (piece.custom()) {  // its shape, as the layout gives it
      std::snprintf(line, sizeof line, "%s%.0f mm", piece.turn ? " " : "       ", piece.length(0));
      out += line;
      if (piece.turn) {
        std::snprintf(line, sizeof line, ", r %g mm, %g°", piece.radius(), piece.angle());
        out += line;
      }
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    out += "\n";
  }
  out += "lap length:";
  for (double o : kLaneOffsetsMm) {
    std::snprintf(line, sizeof line, " %.0f mm at %+.0f,", track.lapLength(o), o);
    out += line;
  }
  out.pop_back();
  std::snprintf(line, sizeof line, "\nfloor space: %.2f m × %.2f m (road edges)\n",
                (b["maxX"].get<double>() - b["minX"].get<double>()) / 1000,
                (b["maxY"].get<double>() - b["minY"].get<double>()) / 1000);
  out += line;
  return out;
}

}  // namespace pitwall::view
