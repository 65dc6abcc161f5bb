#pragma once
// MindRoad instructions as JSON objects for `pitwall decode mindroad`:
// {"name":"steering","id":2,"header":"0x22","x":127,"y":0}.
#include <nlohmann/json.hpp>

#include "engine/protocol/mindroad/codec.hpp"

namespace pitwall::mindroad {

nlohmann::json toJson(const Instruction& instruction);
// The robot's contact answer: {"name":"contact-answer","byte":"0x4b","text":"K"}.
nlohmann::json contactAnswerJson();

}  // namespace pitwall::mindroad
