// Captures without times (docs/cli.md "Captures without times"): the real car's frames of
// tests/realdata timed by its own reports, or at a stated interval.
#include "engine/record/capture.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "engine/protocol/anki/codec.hpp"

using namespace pitwall;

namespace {

const std::string kOkoeth = PITWALL_SOURCE_DIR "/tests/realdata/okoeth/";

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  REQUIRE_MESSAGE(in, path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

RecordKind kindOf(const std::string& text) {
  std::istringstream in(text);
  RecordKind kind = recordKind(in);
  CHECK(in.tellg() == 0);  // put back at its start
  return kind;
}

TimedCapture timed(const std::string& text, CaptureTiming timing = {}) {
  std::istringstream in(text);
  RecordKind kind = recordKind(in);
  REQUIRE(kind != RecordKind::Timed);
  auto result = timeCapture(in, kind, timing);
  REQUIRE_MESSAGE(result.ok(), result.error());
  return std::move(*result);
}

// The median time between transitions (each a whole piece, the first one's start not seen);
// every one of them positive and below 3 s.
double pieceMedian(const std::vector<double>& transitions) {
  REQUIRE(transitions.size() >= 10);
  std::vector<double> pieces;
  for (std::size_t i = 1; i < transitions.size(); ++i) {
    const double d = transitions[i] - transitions[i - 1];
    CHECK(d > 0.1);
    CHECK(d < 3.0);
    pieces.push_back(d);
  }
  std::sort(pieces.begin(), pieces.end());
  return pieces[pieces.size() / 2];
}

Record recordOf(const TimedCapture& capture) {
  std::istringstream in(capture.record);
  return readRecord(in);
}

}  // namespace

TEST_CASE("capture: a record, a capture's lines and JSON lines without times are told apart") {
  CHECK(kindOf(R"({"t":0.1,"car":1,"dir":"rx","hex":"01 17"})"
               "\n") == RecordKind::Timed);
  CHECK(kindOf("\n  \n"
               R"({"car":1,"dir":"rx","hex":"01 17"})"
               "\n") == RecordKind::UntimedJson);
  CHECK(kindOf("0 car2_d28ae98b 05 3f 01 00 00 01\n") == RecordKind::CaptureText);
  CHECK(kindOf(fileText(kOkoeth + "lane3_speed750.txt")) == RecordKind::CaptureText);
  // what is neither is a record, whose bad lines a replay names
  for (const std::string& hostile :
       {std::string(""), std::string("garbage\n"), std::string(100000, '[') + "\n",
        std::string("{\"t\":-5,\"car\":1,\"dir\":\"rx\",\"hex\":\"01 17\"}\n"),
        std::string("{\"car\":1}\n"), std::string("12 car zz\n"), std::string("\xff\xfe 1 2\n")})
    CHECK(kindOf(hostile) == RecordKind::Timed);
}

TEST_CASE("capture: a record whose \"t\" counts its frames is told from one in seconds") {
  auto lines = [](std::initializer_list<const char*> ts) {
    std::string text;
    for (const char* t : ts)
      text += std::string(R"({"t":)") + t + R"(,"car":1,"dir":"rx","hex":"01 17"})" + "\n";
    return text;
  };
  CHECK(kindOf(lines({"0", "1", "2", "3"})) == RecordKind::IndexedJson);
  CHECK(kindOf(lines({"5", "6", "7"})) == RecordKind::IndexedJson);
  CHECK(kindOf(lines({"0.0", "1.0", "2.0"})) == RecordKind::IndexedJson);
  CHECK(kindOf(lines({"0", "1", "3"})) == RecordKind::Timed);
  CHECK(kindOf(lines({"0", "0.5", "1"})) == RecordKind::Timed);
  CHECK(kindOf(lines({"0.01", "0.02", "0.03"})) == RecordKind::Timed);
  CHECK(kindOf(lines({"0", "1"})) == RecordKind::Timed);  // too little to tell
  CHECK(kindOf(lines({"0", "1"}) + "garbage\n") == RecordKind::Timed);
  // timed as a capture: the index is left aside
  const TimedCapture capture = timed(lines({"0", "1", "2"}));
  CHECK(capture.frames == 3);
  CHECK(recordOf(capture).frames[2].t < 1);  // 10 ms apart, not a second
}

TEST_CASE("capture: the real car's frames timed by its speeds and wheel distances") {
  const std::string text = fileText(kOkoeth + "lane3_speed750.txt");
  const TimedCapture capture = timed(text);
  Record record = recordOf(capture);
  CHECK(record.bad.empty());
  std::size_t lines = 0;
  for (char c : text) lines += c == '\n';
  CHECK(capture.frames == lines);
  REQUIRE(record.frames.size() == lines);
  CHECK(record.names.at(1) == "car2_d28ae98b");
  CHECK(capture.inferred * 10 >= capture.frames * 7);  // most frames lie on a timed piece
  CHECK(capture.how.find("inferred") != std::string::npos);
  // Each piece took its wheel distance at its speed: at 750 mm/s a piece of the oval (about
  // 430–640 mm on lane 3) takes 0.5–0.95 s; the frames keep the capture's order.
  std::vector<double> transitions;
  for (const auto& f : record.frames) {
    auto m = anki::decode(f.bytes);
    REQUIRE(m.ok());
    if (std::holds_alternative<anki::TransitionUpdate>(*m)) transitions.push_back(f.t);
  }
  CHECK(pieceMedian(transitions) > 0.5);
  CHECK(pieceMedian(transitions) < 0.9);
  std::istringstream again(text);
  std::vector<std::string> hex;
  for (std::string line; std::getline(again, line);) {
    const auto car = line.find(' ');
    hex.push_back(line.substr(line.find(' ', car + 1) + 1));
  }
  for (std::size_t i = 1; i < record.frames.size(); ++i)
    CHECK(record.frames[i].t >= record.frames[i - 1].t);
  // the bytes unchanged, in their order
  std::istringstream recordText(capture.record);
  std::size_t i = 0;
  for (std::string line; std::getline(recordText, line); ++i)
    CHECK(line.find(hex[i]) != std::string::npos);
}

TEST_CASE("capture: at 250 mm/s the same pieces take three times as long") {
  const TimedCapture slow = timed(fileText(kOkoeth + "lane3_speed250.txt"));
  Record record = recordOf(slow);
  std::vector<double> transitions;
  for (const auto& f : record.frames)
    if (auto m = anki::decode(f.bytes); m && std::holds_alternative<anki::TransitionUpdate>(*m))
      transitions.push_back(f.t);
  CHECK(pieceMedian(transitions) > 1.6);
  CHECK(pieceMedian(transitions) < 2.7);
}

TEST_CASE("capture: a stated interval times every frame by its place") {
  const TimedCapture capture = timed(fileText(kOkoeth + "lane1_speed750.txt"), CaptureTiming{0.05});
  CHECK(capture.inferred == 0);
  CHECK(capture.how.find("stated interval") != std::string::npos);
  Record record = recordOf(capture);
  REQUIRE(record.frames.size() == capture.frames);
  for (std::size_t i = 0; i < record.frames.size(); ++i)
    CHECK(record.frames[i].t == doctest::Approx(0.05 * static_cast<double>(i)));
}

TEST_CASE("capture: JSON lines without times keep their cars, directions and names") {
  const TimedCapture capture =
      timed(R"({"car":2,"dir":"tx","hex":"06 24 ee 02 e8 03 00","carName":"red"})"
            "\n"
            R"({"car":2,"dir":"rx","hex":"03 36 ee 02"})"
            "\n"
            R"({"car":3,"dir":"rx","hex":"01 17","carName":"blue"})"
            "\n");
  Record record = recordOf(capture);
  REQUIRE(record.frames.size() == 3);
  CHECK(record.names.at(2) == "red");
  CHECK(record.names.at(3) == "blue");
  CHECK(record.frames[0].tx);
  CHECK(record.frames[0].car == 2);
}

TEST_CASE("capture: hostile lines are counted with why, the frames around them kept") {
  std::string text = "0 a 01 17\n";
  text += "1 a zz\n";                      // no hex
  text += "x a 01 17\n";                   // no index
  text += "2 a\n";                         // no frame
  text += std::string(70000, '7') + "\n";  // longer than a line may be
  text += "3 \xff\xfe 01 17\n";            // a name that is no UTF-8
  text += "4 a 01 17\n";
  const TimedCapture capture = timed(text);
  CHECK(capture.frames == 3);
  CHECK(capture.bad.count == 4);
  Record record = recordOf(capture);
  CHECK(record.bad.empty());  // what it wrote is whole
  REQUIRE(record.frames.size() == 3);
  CHECK(record.names.at(2).find("\\xff") != std::string::npos);  // shown, not passed on raw
  for (const auto& b : capture.bad.first) CHECK(b.why.size() < 200);
}

TEST_CASE("capture: more cars than a record holds is a sentence, not a crash") {
  std::string text;
  for (int i = 0; i <= kMaxRecordedCar; ++i) text += "0 car" + std::to_string(i) + " 01 17\n";
  std::istringstream in(text);
  auto result = timeCapture(in, RecordKind::CaptureText, {});
  REQUIRE_FALSE(result.ok());
  CHECK(result.error().find("more than 64 cars") != std::string::npos);
}
