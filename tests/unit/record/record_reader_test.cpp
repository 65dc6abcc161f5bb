#include "engine/record/record_reader.hpp"

#include <doctest/doctest.h>

#include <sstream>

using namespace pitwall;

namespace {

const std::string kLine =
    R"({"t":0.330000,"car":1,"dir":"rx","hex":"10 27 05 11 00 00 00 00 58 02 40 00 00 00 00 00 00",)"
    R"("msg":{"id":"0x27","name":"position-update"}})";

RecordedFrame frameOf(std::string_view line, double lastTime = 0) {
  auto parsed = parseRecordLine(line, lastTime);
  REQUIRE_MESSAGE(std::holds_alternative<RecordedFrame>(parsed), std::get<std::string>(parsed));
  return std::get<RecordedFrame>(parsed);
}

std::string whyNot(std::string_view line, double lastTime = 0) {
  auto parsed = parseRecordLine(line, lastTime);
  REQUIRE_MESSAGE(std::holds_alternative<std::string>(parsed), "the line was taken as a frame");
  return std::get<std::string>(parsed);
}

// Every character of an error can go to a terminal: printable ASCII (and the ellipsis of a cut).
bool printable(const std::string& text) {
  std::string rest = text;
  for (auto at = rest.find("…"); at != rest.npos; at = rest.find("…")) rest.erase(at, 3);
  for (unsigned char c : rest)
    if (c < 0x20 || c >= 0x7f) return false;
  return true;
}

std::string nested(int depth) {
  return std::string(depth, '[') + std::string(depth, ']');
}

Record read(const std::string& text) {
  std::istringstream in(text);
  return readRecord(in);
}

}  // namespace

TEST_CASE("a line as the recorder writes it is a frame: time, car, direction and bytes") {
  RecordedFrame f = frameOf(kLine);
  CHECK(f.t == doctest::Approx(0.33));
  CHECK(f.car == 1);
  CHECK_FALSE(f.tx);
  REQUIRE(f.bytes.size() == 17);
  CHECK(f.bytes[0] == 0x10);
  CHECK(f.bytes[1] == 0x27);
  CHECK(frameOf(R"({"t":1,"car":64,"dir":"tx","hex":"06 24 e8 03 a8 61 00"})").tx);
}

TEST_CASE("the bytes come from \"hex\", never from \"msg\"") {
  // a msg that says something else, and none at all
  RecordedFrame f = frameOf(R"({"t":1,"car":2,"dir":"rx","hex":"01 17","msg":{"name":"x"}})");
  CHECK(f.bytes == std::vector<std::uint8_t>{0x01, 0x17});
  CHECK(frameOf(R"({"t":1,"car":2,"dir":"rx","hex":"0117"})").bytes.size() == 2);
  CHECK(frameOf(R"({"t":1,"car":2,"dir":"rx","hex":"0A 1B"})").bytes ==
        std::vector<std::uint8_t>{0x0a, 0x1b});
}

TEST_CASE("a line that is not a frame is set aside with the reason") {
  struct Case {
    std::string line, why;
  };
  const Case cases[] = {
      {"garbage", "not JSON"},
      {R"({"t":1,"car":1,"dir":"rx","hex":"01 17")", "not JSON"},  // cut short
      {"[1,2]", "not a JSON object"},
      {R"({"car":1,"dir":"rx","hex":"01 17"})", R"(no "t")"},
      {R"({"t":"1","car":1,"dir":"rx","hex":"01 17"})", R"("t" is not a number)"},
      {R"({"t":-0.5,"car":1,"dir":"rx","hex":"01 17"})", "out of range"},
      {R"({"t":1e300,"car":1,"dir":"rx","hex":"01 17"})", "out of range"},
      {R"({"t":1e400,"car":1,"dir":"rx","hex":"01 17"})", "not JSON"},  // beyond a double
      {R"({"t":1,"dir":"rx","hex":"01 17"})", R"(no "car")"},
      {R"({"t":1,"car":0,"dir":"rx","hex":"01 17"})", R"("car" must be an integer 1..64, not 0)"},
      {R"({"t":1,"car":65,"dir":"rx","hex":"01 17"})", "not 65"},
      {R"({"t":1,"car":1.5,"dir":"rx","hex":"01 17"})", "not 1.5"},
      {R"({"t":1,"car":"1","dir":"rx","hex":"01 17"})", "must be an integer"},
      {R"({"t":1,"car":18446744073709551615,"dir":"rx","hex":"01 17"})", "must be an integer"},
      {R"({"t":1,"car":-9223372036854775808,"dir":"rx","hex":"01 17"})", "must be an integer"},
      {R"({"t":1,"car":99999999999999999999999,"dir":"rx","hex":"01 17"})", "must be an integer"},
      {R"({"t":1,"car":1,"hex":"01 17"})", R"(no "dir")"},
      {R"({"t":1,"car":1,"dir":"up","hex":"01 17"})", R"("dir" must be "rx" or "tx")"},
      {R"({"t":1,"car":1,"dir":"rx"})", R"(no "hex")"},
      {R"({"t":1,"car":1,"dir":"rx","hex":17})", R"("hex" is not a string)"},
      {R"({"t":1,"car":1,"dir":"rx","hex":""})", R"("hex" is empty)"},
      {R"({"t":1,"car":1,"dir":"rx","hex":"01 1"})", R"("hex")"},
      {R"({"t":1,"car":1,"dir":"rx","hex":"zz"})", R"("hex")"},
      {"{\"t\":1,\"car\":1,\"dir\":\"rx\",\"hex\":\"\xff\xfe\"}", "ill-formed UTF-8"},
      {"{\"t\":1,\"car\":1,\"dir\":\"r\xc3\x28\",\"hex\":\"01\"}", "ill-formed UTF-8"},
      {"{\"t\":\xff}", "not JSON"},
      {std::string("\0\0\0", 3), "not JSON"},
      {nested(10000), "nested deeper than 16"},
      {std::string(30000, '['), "nested deeper than 16"},
      {R"({"t":1,"car":1,"dir":"rx","hex":"01 17","msg":)" + nested(100) + "}",
       "nested deeper than 16"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.line.substr(0, 80));
    std::string why = whyNot(c.line);
    CHECK_MESSAGE(why.find(c.why) != std::string::npos, why);
    CHECK_MESSAGE(printable(why), why);
    CHECK(why.size() < 240);
  }
}

TEST_CASE("a frame may lie a millisecond before the one before it, not more") {
  const std::string at5 = R"({"t":5.0,"car":1,"dir":"rx","hex":"01 17"})";
  const std::string justBefore = R"({"t":4.9995,"car":1,"dir":"rx","hex":"01 17"})";
  CHECK(frameOf(justBefore, 5.0).t == doctest::Approx(4.9995));
  std::string why = whyNot(R"({"t":4.5,"car":1,"dir":"rx","hex":"01 17"})", 5.0);
  CHECK(why.find("goes back in time") != std::string::npos);
  CHECK(frameOf(at5, 5.0).t == 5.0);
}

TEST_CASE("a record cut short and corrupted in the middle keeps its whole lines, numbered") {
  const std::string good = R"({"t":1,"car":1,"dir":"rx","hex":"01 17"})";
  Record r = read(good + "\n" +       // 1
                  "garbage \xff\n" +  // 2
                  "\n" +              // 3: blank, skipped
                  R"({"t":2,"car":2,"dir":"tx","hex":"01 16"})"
                  "\r\n"                                  // 4: CRLF
                  + R"({"t":3,"car":1,"dir":"rx","he)");  // 5: the last line, cut
  REQUIRE(r.frames.size() == 2);
  CHECK(r.frames[0].line == 1);
  CHECK(r.frames[1].line == 4);
  CHECK(r.frames[1].tx);
  REQUIRE(r.bad.size() == 2);
  CHECK(r.bad[0].line == 2);
  CHECK(r.bad[0].why.find("not JSON") == 0);
  CHECK(printable(r.bad[0].why));
  CHECK(r.bad[1].line == 5);
  CHECK(r.bad[1].why.find("not JSON") == 0);
}

TEST_CASE("a line over 64 KiB is skipped unread, and the lines after it are read") {
  const std::string good = R"({"t":1,"car":1,"dir":"rx","hex":"01 17"})";
  std::string huge = R"({"t":1,"car":1,"dir":"rx","hex":")" + std::string(1 << 20, 'a') + "\"}";
  Record r = read(good + "\n" + huge + "\n" + good + "\n" + huge);  // the last one without \n
  REQUIRE(r.frames.size() == 2);
  CHECK(r.frames[1].line == 3);
  REQUIRE(r.bad.size() == 2);
  CHECK(r.bad[0].line == 2);
  CHECK(r.bad[0].why == "a line of " + std::to_string(huge.size()) +
                            " bytes, longer than 65536: not a frame of a record");
  CHECK(r.bad[1].line == 4);
}

TEST_CASE("a line of exactly 64 KiB is read; one byte more is not") {
  const std::string good = R"({"t":1,"car":1,"dir":"rx","hex":"01 17"})";
  std::string padded = good + std::string(kMaxLineBytes - good.size(), ' ');
  Record r = read(padded + "\n" + padded + " \n");
  CHECK(r.frames.size() == 1);
  REQUIRE(r.bad.size() == 1);
  CHECK(r.bad[0].line == 2);
}

TEST_CASE("an empty record has no frames and no bad lines") {
  Record r = read("");
  CHECK(r.frames.empty());
  CHECK(r.bad.empty());
  CHECK(read("\n\n  \n").frames.empty());
}

TEST_CASE("record reader: one frame from far ahead does not take every frame after it") {
  auto line = [](double t) {
    return R"({"t":)" + std::to_string(t) + R"(,"car":1,"dir":"rx","hex":"01 17"})" + "\n";
  };
  std::istringstream in(line(1.0) + line(1.1) + line(900.0) + "junk\n" + line(1.2) + line(1.3) +
                        line(1.25) + line(1.4));
  Record r = readRecord(in);
  std::vector<std::size_t> kept;
  for (const auto& f : r.frames) kept.push_back(f.line);
  // 900 (line 3) is the odd one out; 1.25 after 1.3 is jitter gone back: refused itself
  CHECK(kept == std::vector<std::size_t>{1, 2, 5, 6, 8});
  REQUIRE(r.bad.size() == 3);
  CHECK(r.bad[0].line == 3);
  CHECK(r.bad[0].why.find("lies ahead of the frames around it") != std::string::npos);
  CHECK(r.bad[1].line == 4);
  CHECK(r.bad[2].line == 7);
  CHECK(r.bad[2].why.find("goes back in time") != std::string::npos);
}

TEST_CASE("record reader: the cars' names and the layout a record keeps; odd ones are not taken") {
  std::istringstream in(
      R"({"t":0,"car":1,"dir":"tx","hex":"01 17","layout":"start S L L S S L L","carName":"skull"})"
      "\n"
      R"({"t":0,"car":2,"dir":"tx","hex":"01 17","carName":"bad\u0007bell"})"
      "\n"
      R"({"t":0,"car":3,"dir":"tx","hex":"01 17","carName":42,"layout":["S"]})"
      "\n" +
      std::string(R"({"t":0,"car":4,"dir":"tx","hex":"01 17","carName":")") + std::string(65, 'x') +
      "\"}\n" + R"({"t":1,"car":1,"dir":"rx","hex":"01 17","carName":"later"})" + "\n");
  Record r = readRecord(in);
  CHECK(r.bad.empty());  // still frames: only the extra is not taken
  REQUIRE(r.frames.size() == 5);
  CHECK(r.layout == "start S L L S S L L");
  CHECK(r.names.size() == 1);
  CHECK(r.names.at(1) == "skull");  // a car's first name stays
}

TEST_CASE("record scan: bad lines are counted, only the first 20 kept, in line order") {
  auto line = [](double t, int car, const char* dir) {
    return R"({"t":)" + std::to_string(t) + R"(,"car":)" + std::to_string(car) + R"(,"dir":")" +
           dir + R"(","hex":"01 17","carName":"c)" + std::to_string(car) + "\"}\n";
  };
  // a frame from far ahead (line 2) is told only by the frame after it, after 10 000 bad lines:
  // it still takes its place in line order among the first kept
  std::string text = line(1.0, 1, "rx") + line(900.0, 2, "rx");
  for (int i = 0; i < 10'000; ++i) text += "junk\n";
  text += line(1.5, 2, "tx") + line(2.0, 3, "rx");
  std::istringstream in(text);
  RecordSummary s = scanRecord(in);
  CHECK(s.frames == 3);
  CHECK(s.duration == doctest::Approx(2.0));
  CHECK(s.bad.count == 10'001);
  REQUIRE(s.bad.first.size() == kBadLinesKept);
  CHECK(s.bad.first[0].line == 2);
  CHECK(s.bad.first[0].why.find("lies ahead of the frames around it") != std::string::npos);
  CHECK(s.bad.first[1].line == 3);
  CHECK(s.bad.first.back().line == kBadLinesKept + 1);
  // every car with a frame, its tx frames counted; the names its frames carry
  CHECK(s.framesOut == std::map<int, std::uint64_t>{{1, 0}, {2, 1}, {3, 0}});
  CHECK(s.names == std::map<int, std::string>{{1, "c1"}, {2, "c2"}, {3, "c3"}});
}

TEST_CASE("record stream: the same frames as readRecord, one at a time, again after a rewind") {
  std::string text;
  for (int i = 0; i < 50; ++i)
    text += R"({"t":)" + std::to_string(i * 0.1) + R"(,"car":1,"dir":"rx","hex":"01 17"})" +
            (i % 7 == 3 ? "\ngarbage\n" : "\n");
  const Record whole = read(text);
  std::istringstream in(text);
  RecordStream stream(in);
  for (int pass = 0; pass < 2; ++pass) {
    CAPTURE(pass);
    std::vector<std::size_t> lines;
    while (auto f = stream.next()) lines.push_back(f->line);
    REQUIRE(lines.size() == whole.frames.size());
    for (std::size_t i = 0; i < lines.size(); ++i) CHECK(lines[i] == whole.frames[i].line);
    CHECK(stream.bad().count == whole.bad.size());
    REQUIRE(stream.rewind());
  }
}

TEST_CASE("record reader: a link line is the car's link going down or up, kept apart from frames") {
  RecordedFrame down =
      frameOf(R"({"t":12.5,"car":3,"link":{"up":false,"reason":"the link dropped","connects":1,)"
              R"("drops":1,"writeFailures":4,"stalls":1,"rssi":-71}})");
  CHECK(down.car == 3);
  CHECK(down.bytes.empty());
  REQUIRE(down.link);
  CHECK_FALSE(down.link->up);
  CHECK(down.link->reason == "the link dropped");
  CHECK(down.link->writeFailures == 4);
  CHECK(down.link->stalls == 1);
  CHECK(down.link->rssi == -71);
  RecordedFrame up = frameOf(R"({"t":14,"car":3,"link":{"up":true,"reason":null,"rssi":null}})");
  REQUIRE(up.link);
  CHECK(up.link->up);
  CHECK_FALSE(up.link->rssi);
  // a reason with control characters reaches no terminal as they are
  RecordedFrame odd =
      frameOf("{\"t\":1,\"car\":1,\"link\":{\"up\":false,\"reason\":\"a\\u001b[2Jb\"}}");
  CHECK(printable(odd.link->reason));

  Record r = read(kLine + "\n" + R"({"t":0.5,"car":1,"link":{"up":false,"reason":"x"}})" + "\n" +
                  R"({"t":0.6,"car":1,"link":{"up":true}})" + "\n");
  CHECK(r.frames.size() == 1);
  CHECK(r.links.size() == 2);
  CHECK(r.bad.empty());
  std::istringstream in(kLine + "\n" + R"({"t":0.5,"car":2,"link":{"up":false,"reason":"x"}})" +
                        "\n");
  RecordSummary s = scanRecord(in);
  CHECK(s.frames == 1);
  CHECK(s.drops[2] == 1);
  CHECK(s.framesOut.count(2) == 1);  // a car the record names only in a link line is a car
}

TEST_CASE("record reader: a hostile link line is set aside with the reason") {
  struct Case {
    std::string line, why;
  };
  const Case cases[] = {
      {R"({"t":1,"car":1,"link":7})", R"("link" is not an object)"},
      {R"({"t":1,"car":1,"link":{}})", R"("link" needs "up")"},
      {R"({"t":1,"car":1,"link":{"up":"yes"}})", R"("link" needs "up")"},
      {R"({"t":1,"car":1,"link":{"up":false,"reason":[1]}})", R"("reason" is not a string)"},
      {R"({"t":1,"car":1,"link":{"up":true,"stalls":-1}})", R"("stalls" must be a count)"},
      {R"({"t":1,"car":1,"link":{"up":true,"writeFailures":1e300}})", "must be a count"},
      {R"({"t":1,"car":1,"link":{"up":true,"writeFailures":99999999999999999999999}})",
       "must be a count"},
      {R"({"t":1,"car":1,"link":{"up":true,"rssi":-300}})", R"("rssi" must be dBm)"},
      {R"({"t":1,"car":1,"link":{"up":true,"rssi":"-60"}})", R"("rssi" must be dBm)"},
      {R"({"t":1,"car":0,"link":{"up":true}})", R"("car" must be an integer 1..64)"},
      {R"({"t":1,"car":1,"link":{"up":true,"x":)" + nested(100) + "}}", "nested deeper than 16"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.line.substr(0, 80));
    std::string why = whyNot(c.line);
    CHECK_MESSAGE(why.find(c.why) != std::string::npos, why);
    CHECK_MESSAGE(printable(why), why);
  }
}
