#pragma once
// The terminal's keyboard as one player's controller (docs/controllers.md), for testing without a
// phone: ↑/↓ throttle up and down in steps, ←/→ lanes, space brakes to 0. It takes the first
// free human seat. The terminal stays in cbreak mode (no echo, keys one by one, Ctrl-C still a
// signal, Ctrl-Z off) while it drives and is restored when it is destroyed.
#include <boost/system/error_code.hpp>
#include <memory>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/drive/seats.hpp"

namespace pitwall::drive {

class Keyboard {
 public:
  Keyboard(Loop& loop, Seats& seats, int fd);  // fd: the terminal (stdin)
  ~Keyboard();                                 // restores the terminal
  Keyboard(const Keyboard&) = delete;
  Keyboard& operator=(const Keyboard&) = delete;

  // Takes a seat and starts reading; the error says why not (not a terminal; no free seat).
  Result<bool, std::string> start();

  // What the keyboard does when its wait for the terminal ends with `ec` (the Asio handler): a
  // cancel is nothing, an error lets go of the seat. Public for the tests — no terminal makes
  // Asio's wait fail on purpose.
  void waited(const boost::system::error_code& ec);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pitwall::drive
