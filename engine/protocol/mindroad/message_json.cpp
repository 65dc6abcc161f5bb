// MindRoad instructions as JSON. Buttons carry the raw byte and both of the seed's readings
// (mindroad.md, the buttons decision): `button` (table 2: the byte is one button's id, null for
// 4–255) and `pressed` (§5.2: the byte is a bit mask; bit n is button n, unnamed bits as "bit-n").
#include "engine/protocol/mindroad/message_json.hpp"

#include <type_traits>

#include "engine/core/hex.hpp"

namespace pitwall::mindroad {

nlohmann::json toJson(const Instruction& instruction) {
  nlohmann::json j;
  j["name"] = name(instruction);
  j["id"] = instructionId(instruction);
  j["header"] = hexByte(encode(instruction).bytes[0]);
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, Steering>) {
          j["x"] = m.x;
          j["y"] = m.y;
        } else if constexpr (std::is_same_v<T, MousePosition>) {
          j["x"] = m.x;
          j["y"] = m.y;
        } else if constexpr (std::is_same_v<T, Buttons>) {
          j["raw"] = m.raw;
          if (auto b = m.asId())
            j["button"] = buttonName(*b);
          else
            j["button"] = nullptr;
          auto pressed = nlohmann::json::array();
          for (int bit = 0; bit < 8; ++bit) {
            if (!m.pressed(bit)) continue;
            if (bit < 4)
              pressed.push_back(buttonName(static_cast<Button>(bit)));
            else
              pressed.push_back("bit-" + std::to_string(bit));
          }
          j["pressed"] = pressed;
        } else if constexpr (std::is_same_v<T, PictureMode>) {
          j["mode"] = pictureName(m.mode);
        }
      },
      instruction);
  return j;
}

nlohmann::json contactAnswerJson() {
  return {{"name", "contact-answer"}, {"byte", "0x4b"}, {"text", "K"}};
}

}  // namespace pitwall::mindroad
