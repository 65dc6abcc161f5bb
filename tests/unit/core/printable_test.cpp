#include "engine/core/printable.hpp"

#include <doctest/doctest.h>

#include <cstdio>
#include <string>

using namespace pitwall;

TEST_CASE("printable keeps printable ASCII and well-formed UTF-8, and shows other bytes as \\xNN") {
  CHECK(printable("speed") == "speed");
  CHECK(printable("vitésse") == "vitésse");
  CHECK(printable(std::string("a\0b\n", 4)) == "a\\x00b\\x0a");
  CHECK(printable("\x7f") == "\\x7f");
  CHECK(printable("\xc3") == "\\xc3");                    // a UTF-8 start with nothing after it
  CHECK(printable("\xc0\xaf") == "\\xc0\\xaf");           // an overlong form
  CHECK(printable("\xed\xa0\x80") == "\\xed\\xa0\\x80");  // a surrogate
  CHECK(printable("\xf4\x90\x80\x80") == "\\xf4\\x90\\x80\\x80");  // beyond U+10FFFF
  CHECK(printable("\xf0\x9f\x8f\x81") == "\xf0\x9f\x8f\x81");      // 🏁
}

TEST_CASE("printable cuts a long text after maxBytes of it, and says so") {
  CHECK(printable(std::string(100, 'x'), 10) == std::string(10, 'x') + "…");
  CHECK(printable("short", 10) == "short");
  CHECK(printable("exactly10!", 10) == "exactly10!");
  // the limit is on what is shown: escapes count four bytes each
  CHECK(printable(std::string(100, '\x01'), 20) == "\\x01\\x01\\x01\\x01\\x01…");
  CHECK(printable("ééé", 5) == "éé…");
  CHECK(utf8Length("é") == 2);
  CHECK(utf8Length("e") == 0);
}

// Found by the record reader's fuzzer through a capture's bad line: F5–FF followed by two
// continuation bytes were taken for a 3-byte character and passed through raw.
TEST_CASE("printable: bytes that never lead a UTF-8 character are escaped, whatever follows") {
  for (unsigned lead = 0xf5; lead <= 0xff; ++lead) {
    const std::string bytes = {static_cast<char>(lead), '\x8c', '\x8c', '\x8c'};
    CHECK(utf8Length(bytes) == 0);
    char escaped[8];
    std::snprintf(escaped, sizeof escaped, "\\x%02x", lead);
    CHECK(printable(bytes) == std::string(escaped) + "\\x8c\\x8c\\x8c");
  }
  CHECK(utf8Length("\xc0\x80") == 0);  // overlong forms of NUL
  CHECK(utf8Length("\xc1\xbf") == 0);
  CHECK(utf8Length("\xef\xbf\xbf") == 3);      // U+FFFF, the last 3-byte character
  CHECK(utf8Length("\xf4\x8f\xbf\xbf") == 4);  // U+10FFFF, the last there is
}
