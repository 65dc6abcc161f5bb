#pragma once
// Controller→vehicle commands written as words, as `pitwall encode anki MESSAGE ARGS…` takes them:
//   sdk-mode on|off [FLAGS]   set-speed SPEED [ACCEL] [respect-limit]
//   change-lane HSPEED HACCEL OFFSET [HOP TAG]   set-offset OFFSET   cancel-lane-change
//   turn left|right|uturn|uturn-jump|none [immediate|intersection]
//   ping | version | battery | disconnect   lights MASK
//   lights-pattern CHANNEL EFFECT START END CYCLES [CHANNEL EFFECT START END CYCLES]…
//   config PARSE_MASK plastic|vinyl|0|1
// Numbers may be decimal or 0x-hex. Errors name the word, the value and the accepted range.
#include <span>
#include <string>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/anki/messages.hpp"

namespace pitwall::anki {

Result<Message, std::string> parseCommand(std::span<const std::string> words);
// The list of command forms above, for help texts.
std::vector<std::string> commandForms();

}  // namespace pitwall::anki
