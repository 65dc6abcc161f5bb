// The terminal's driving keys (engine/drive/key_parser.hpp): arrows in both cursor modes, space,
// sequences split anywhere across reads, and bytes no terminal should send.
#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

#include "engine/drive/key_parser.hpp"

using namespace pitwall::drive;
using Keys = std::vector<Key>;

TEST_CASE("keys: arrows as CSI (ESC, bracket) and SS3 (ESC O), and space") {
  KeyParser p;
  CHECK(p.feed("\x1b[A\x1b[B\x1b[C\x1b[D") == Keys{Key::Up, Key::Down, Key::Right, Key::Left});
  CHECK(p.feed("\x1bOA\x1bOB\x1bOC\x1bOD") == Keys{Key::Up, Key::Down, Key::Right, Key::Left});
  CHECK(p.feed(" ") == Keys{Key::Space});
  CHECK(p.feed("  ") == Keys{Key::Space, Key::Space});
}

TEST_CASE("keys: an arrow with a modifier (xterm's CSI 1;5A) is the same arrow") {
  KeyParser p;
  CHECK(p.feed("\x1b[1;5A\x1b[1;2D") == Keys{Key::Up, Key::Left});
}

TEST_CASE("keys: a sequence split at every byte across reads still makes its key") {
  const std::string all = "\x1b[A \x1bOC\x1b[1;5B\x1b[D";
  const Keys want{Key::Up, Key::Space, Key::Right, Key::Down, Key::Left};
  for (std::size_t cut = 0; cut <= all.size(); ++cut) {
    KeyParser p;
    Keys got = p.feed(all.substr(0, cut));
    Keys rest = p.feed(all.substr(cut));
    got.insert(got.end(), rest.begin(), rest.end());
    CHECK_MESSAGE(got == want, "cut at " << cut);
  }
  KeyParser p;  // one byte a read
  Keys got;
  for (char c : all) {
    Keys k = p.feed(std::string(1, c));
    got.insert(got.end(), k.begin(), k.end());
  }
  CHECK(got == want);
}

TEST_CASE("keys: letters, other sequences and Alt+key are no driving keys") {
  KeyParser p;
  CHECK(p.feed("wasdABCD\r\n\t\x7f").empty());                 // bare A–D are letters, not arrows
  CHECK(p.feed("\x1b[H\x1b[F\x1b[5~\x1b[15~\x1bOP").empty());  // Home, End, PgUp, F5, F1
  CHECK(p.feed("\x1b"
               "a")
            .empty());                       // Alt+a
  CHECK(p.feed("\x1b[<0;12;7M").empty());    // an SGR mouse report
  CHECK(p.feed("\x1b[A") == Keys{Key::Up});  // and then still in step
}

TEST_CASE("keys: ESC then CSI A is a lone Esc then up; a broken sequence restarts on its ESC") {
  KeyParser p;
  CHECK(p.feed("\x1b\x1b[A") == Keys{Key::Up});
  CHECK(p.feed("\x1b[1\x1b[B") == Keys{Key::Down});  // a CSI cut by a new ESC
  CHECK(p.feed("\x1bO\x1b[C") == Keys{Key::Right});  // an SS3 cut by a new ESC
  CHECK(p.feed("\x1b ") == Keys{Key::Space});        // Esc then space: the space counts
}

TEST_CASE("keys: a runaway control sequence is dropped and parsing starts over") {
  KeyParser p;
  CHECK(p.feed("\x1b[" + std::string(10000, '1')).empty());
  CHECK(p.feed("A").empty());  // the letter after the dropped sequence is a letter
  CHECK(p.feed(" \x1b[A") == Keys{Key::Space, Key::Up});
}

TEST_CASE("keys: random bytes, then a clean arrow, always parse (no crash, back in step)") {
  std::mt19937 rng(22);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> len(0, 40);
  KeyParser p;
  for (int i = 0; i < 5000; ++i) {
    std::string junk(static_cast<std::size_t>(len(rng)), '\0');
    for (char& c : junk) c = static_cast<char>(byte(rng));
    for (Key k : p.feed(junk)) CHECK((k >= Key::Up && k <= Key::Space));
  }
  // An unfinished sequence may eat a few bytes; a terminal's next whole key is read after it.
  p.feed("\x18");  // CAN: ends any sequence (no CSI byte)
  CHECK(p.feed("\x1b[A") == Keys{Key::Up});
}
