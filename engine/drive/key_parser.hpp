#pragma once
// The keys of a terminal in cbreak mode that drive a car (docs/controllers.md "Keyboard"): the
// arrows and space, out of the bytes the terminal sends. Pure: engine/drive/keyboard.cpp feeds it
// what it reads, the unit tests feed it anything.
//
// Arrows come as ECMA-48 control sequences: CSI `ESC [ A` (normal cursor mode) or SS3 `ESC O A`
// (application cursor mode, which some terminals start in), A up, B down, C right, D left; with a
// modifier xterm sends `ESC [ 1 ; 5 A`, read as the same arrow. A sequence may be split across
// reads (a slow link, a pty): the parser keeps its state between calls. Any other sequence (F
// keys, Home, a mouse report) is skipped whole; bytes outside a sequence other than space are
// ignored.
#include <cstddef>
#include <string_view>
#include <vector>

namespace pitwall::drive {

enum class Key { Up, Down, Left, Right, Space };

class KeyParser {
 public:
  // The keys the bytes complete, in order.
  std::vector<Key> feed(std::string_view bytes);

 private:
  enum class State { Ground, Escape, Csi, Ss3 };
  State state_ = State::Ground;
  std::size_t length_ = 0;  // bytes of the control sequence so far (a runaway one is dropped)
};

}  // namespace pitwall::drive
