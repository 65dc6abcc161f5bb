#pragma once
// MindRoad instructions written as words, as `pitwall encode mindroad INSTRUCTION ARGS…` takes
// them:
//   stop | contact | ping | shutdown        steer X Y (−128..127 each)
//   click X Y (1..160, 1..120)              buttons NAME|BYTE (manual, automatic,
//   picture-mode rgb|hsv|filter|0..2          sensitivity-up, sensitivity-down, or 0..255)
// Numbers may be decimal or 0x-hex. Errors name the word, the value and the accepted range.
#include <span>
#include <string>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/mindroad/messages.hpp"

namespace pitwall::mindroad {

Result<Instruction, std::string> parseCommand(std::span<const std::string> words);
// The forms above, for help texts and error messages.
std::vector<std::string> commandForms();

}  // namespace pitwall::mindroad
